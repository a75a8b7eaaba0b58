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
    std::vector<double> pooled;
    std::vector<const std::vector<double>*> runs;
    for (const auto& run : ratios)
        if (!run.empty()) {
            runs.push_back(&run);
            pooled.insert(pooled.end(), run.begin(), run.end());
        }
    if (pooled.empty()) return {};
    Ratio r;
    r.ratio = quantile(pooled, 0.5);
    std::mt19937_64 rng(seed);
    std::uniform_int_distribution<std::size_t> pick_run(0, runs.size() - 1);
    std::vector<double> medians, sample;
    medians.reserve(resamples);
    for (int i = 0; i < resamples; ++i) {
        sample.clear();
        for (std::size_t k = 0; k < runs.size(); ++k) {
            const std::vector<double>& run = *runs[runs.size() > 1 ? pick_run(rng) : 0];
            std::uniform_int_distribution<std::size_t> pick_block(0, run.size() - 1);
            for (std::size_t b = 0; b < run.size(); ++b) sample.push_back(run[pick_block(rng)]);
        }
        medians.push_back(quantile(sample, 0.5));
    }
    std::sort(medians.begin(), medians.end());
    r.low = sorted_quantile(medians, 0.025);
    r.high = sorted_quantile(medians, 0.975);
    return r;
}

}  // namespace teapot
