#pragma once
// Robust statistics shared by the estimators.

#include <algorithm>
#include <cstddef>
#include <span>

namespace canyon::core {

/// Median of a non-empty range: the middle value, or the mean of the two middle values for an even size. Reorders the
/// range (nth_element); callers that need its order pass a copy.
[[nodiscard]] inline double median_in_place(std::span<double> values) {
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  if (values.size() % 2 == 1) return *mid;
  return 0.5 * (*mid + *std::max_element(values.begin(), mid));
}

}  // namespace canyon::core
