// Shipped configuration files (see shipped_config.hpp).

#include "canyon/config/shipped_config.hpp"

#include <filesystem>

#ifndef CANYON_CONFIG_DIR
#define CANYON_CONFIG_DIR ""
#endif

namespace canyon::config {

namespace fs = std::filesystem;

std::vector<std::string> shipped_config_folders() {
  std::vector<std::string> folders;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) folders.push_back((exe.parent_path() / ".." / "config").lexically_normal().string());
  const std::string source_config = CANYON_CONFIG_DIR;
  if (!source_config.empty() && (folders.empty() || fs::path(source_config) != fs::path(folders.front()))) {
    folders.push_back(source_config);
  }
  return folders;
}

Result<std::string> find_shipped_config(const std::string& relative) {
  const std::vector<std::string> folders = shipped_config_folders();
  for (const std::string& folder : folders) {
    const fs::path candidate = fs::path(folder) / relative;
    if (fs::exists(candidate)) return candidate.lexically_normal().string();
  }
  std::string searched;
  for (const std::string& folder : folders) {
    if (!searched.empty()) searched += ", ";
    searched += folder;
  }
  return Error{"shipped configuration '" + relative +
               "' not found (searched: " + (searched.empty() ? std::string("no folder") : searched) + ")"};
}

}  // namespace canyon::config
