#pragma once
// Configuration files shipped with canyon (config/): found next to the executable when installed
// (`<executable folder>/../config`, as in the build tree `build/canyon` -> `config/`), else in the source tree the
// executable was built from (tests, build folders elsewhere).

#include <string>
#include <vector>

#include "canyon/core/result.hpp"

namespace canyon::config {

/// The folders searched, in order: `<executable folder>/../config`, then `<source tree>/config`.
[[nodiscard]] std::vector<std::string> shipped_config_folders();

/// The path of `relative` (e.g. "scenarios/urban-severe.yaml") in the first folder that has it. Error naming the
/// file and the folders searched if none has it.
Result<std::string> find_shipped_config(const std::string& relative);

}  // namespace canyon::config
