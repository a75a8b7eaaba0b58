#include "harness/stats.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace teapot {
namespace {

double sorted_quantile(const std::vector<double>& sorted, double q) {
    if (sorted.empty()) return 0;
    double position = q * double(sorted.size() - 1);
    auto below = static_cast<std::size_t>(std::floor(position));
    std::size_t above = std::min(below + 1, sorted.size() - 1);
    double fraction = position - double(below);
    return sorted[below] + (sorted[above] - sorted[below]) * fraction;
}

// SplitMix64 (Steele, Lea and Flood, 2014), the block bootstrap's generator:
// scripts/gen_bench_docs.py steps the same one, so it recomputes every
// interval from the block data bit for bit (std::mt19937_64 and its
// distributions have no exact counterpart in Python's standard library).
struct SplitMix64 {
    std::uint64_t state;
    std::uint64_t next() {
        std::uint64_t z = state += 0x9E3779B97F4A7C15ull;
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    // An index below n: the output modulo n (the bias, under n / 2^64, is nil
    // for block counts).
    std::size_t pick(std::size_t n) { return std::size_t(next() % n); }
};

}  // namespace

double quantile(std::span<const double> samples, double q) {
    std::vector<double> sorted(samples.begin(), samples.end());
    std::sort(sorted.begin(), sorted.end());
    return sorted_quantile(sorted, q);
}

Summary summarize(std::span<const double> samples) {
    std::vector<double> sorted(samples.begin(), samples.end());
    std::sort(sorted.begin(), sorted.end());
    return {sorted_quantile(sorted, 0.5), sorted_quantile(sorted, 0.05), sorted_quantile(sorted, 0.95)};
}

Ratio bootstrap_ratio(std::span<const double> variant, std::span<const double> reference, int resamples,
                      std::uint64_t seed) {
    double reference_median = quantile(reference, 0.5);
    if (variant.empty() || reference.empty() || reference_median <= 0) return {};
    Ratio r;
    r.ratio = quantile(variant, 0.5) / reference_median;
    std::mt19937_64 rng(seed);
    std::vector<double> ratios, a(variant.size()), b(reference.size());
    ratios.reserve(resamples);
    auto resampled_median = [&](std::span<const double> from, std::vector<double>& into) {
        std::uniform_int_distribution<std::size_t> pick(0, from.size() - 1);
        for (double& x : into) x = from[pick(rng)];
        auto middle = into.begin() + into.size() / 2;
        std::nth_element(into.begin(), middle, into.end());
        double m = *middle;
        if (into.size() % 2 == 0) m = 0.5 * (m + *std::max_element(into.begin(), middle));
        return m;
    };
    for (int i = 0; i < resamples; ++i) {
        double numerator = resampled_median(variant, a);
        double denominator = resampled_median(reference, b);
        if (denominator > 0) ratios.push_back(numerator / denominator);
    }
    std::sort(ratios.begin(), ratios.end());
    r.low = sorted_quantile(ratios, 0.025);
    r.high = sorted_quantile(ratios, 0.975);
    return r;
}

Ratio block_bootstrap_ratio(const std::vector<std::vector<double>>& ratios, int resamples, std::uint64_t seed) {
    // Each run sorted, as scripts/gen_bench_docs.py's process_bootstrap takes
    // them: the same picks then give the same samples there.
    std::vector<std::vector<double>> runs;
    std::vector<double> pooled;
    for (const auto& run : ratios)
        if (!run.empty()) {
            runs.push_back(run);
            std::sort(runs.back().begin(), runs.back().end());
            pooled.insert(pooled.end(), run.begin(), run.end());
        }
    if (pooled.empty()) return {};
    Ratio r;
    r.ratio = quantile(pooled, 0.5);
    SplitMix64 rng{seed};
    std::vector<double> medians, sample;
    medians.reserve(resamples);
    for (int i = 0; i < resamples; ++i) {
        sample.clear();
        for (std::size_t k = 0; k < runs.size(); ++k) {
            const std::vector<double>& run = runs[rng.pick(runs.size())];
            for (std::size_t b = 0; b < run.size(); ++b) sample.push_back(run[rng.pick(run.size())]);
        }
        std::sort(sample.begin(), sample.end());
        medians.push_back(sorted_quantile(sample, 0.5));
    }
    std::sort(medians.begin(), medians.end());
    r.low = sorted_quantile(medians, 0.025);
    r.high = sorted_quantile(medians, 0.975);
    return r;
}

}  // namespace teapot
