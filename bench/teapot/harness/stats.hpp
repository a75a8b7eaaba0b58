// Summary statistics of per-frame stage times.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace teapot {

// Linear-interpolated quantile (q in [0, 1]) of unsorted samples; 0 if empty.
double quantile(std::span<const double> samples, double q);

struct Summary {
    double median = 0, p5 = 0, p95 = 0;
};
Summary summarize(std::span<const double> samples);

// Ratio of medians, median(variant) / median(reference), with a percentile
// bootstrap 95% confidence interval: both sample sets are resampled (with
// replacement, independently, each to its own size) `resamples` times and
// the 2.5% and 97.5% quantiles of the resampled ratios are the interval. The
// seed is fixed, so a run's intervals are reproducible. A zero reference
// median gives ratio 0 and interval [0, 0].
struct Ratio {
    double ratio = 0, low = 0, high = 0;
};
Ratio bootstrap_ratio(std::span<const double> variant, std::span<const double> reference, int resamples = 2000,
                      std::uint64_t seed = 0x7ea907);

// Block-wise ratio, bootstrapped over blocks: ratios[run][block] holds, for
// each process (run) and each of its blocks, the ratio of the variant's block
// median to the reference's neighbouring block median. The ratio is the
// median of all blocks' ratios; the 95% interval comes from a two-level
// percentile bootstrap (runs resampled with replacement, then blocks within
// each chosen run), so both block-to-block and run-to-run spread widen it.
// Fixed seed: reproducible, and with SplitMix64 and the pick order of
// scripts/gen_bench_docs.py's process_bootstrap, which recomputes the
// intervals from the committed block data and must agree exactly. Empty
// input gives {0, 0, 0}.
Ratio block_bootstrap_ratio(const std::vector<std::vector<double>>& ratios, int resamples = 2000,
                            std::uint64_t seed = 0x7ea907);

}  // namespace teapot
