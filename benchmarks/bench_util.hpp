#pragma once
// Helpers shared by the whole-step benchmarks: medians and the comma-separated lists of their
// command lines.

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace gpa::bench {

inline double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n == 0 ? 0.0 : (n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]));
}

// "1e4,1e5": positive numbers; throws std::invalid_argument naming the item otherwise.
inline std::vector<double> parse_list(const std::string& text) {
    std::vector<double> out;
    std::size_t start = 0;
    while (start <= text.size()) {
        const std::size_t comma = text.find(',', start);
        const std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        std::size_t used = 0;
        const double v = std::stod(item, &used);
        if (used != item.size() || !(v > 0.0)) throw std::invalid_argument("\"" + item + "\" is not a positive number");
        out.push_back(v);
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return out;
}

}  // namespace gpa::bench
