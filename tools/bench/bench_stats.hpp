// Order statistics the bench commands report (medians of frame times,
// percentiles of per-pixel changes). Copies: the callers keep their samples.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace bench {

// The middle value; the mean of the two middle ones for an even count; 0 for none.
inline double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// The value at fraction p in [0, 1] of the sorted samples (nearest rank); 0 for none.
inline double percentile(std::vector<double> v, double p) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, std::size_t(p * double(v.size() - 1) + 0.5))];
}

} // namespace bench
