#pragma once
// The main() of canyon's executables: runs the program and reports an exception that escaped it as an internal
// error with the program's name (exit status `exit_status`) instead of std::terminate's abort.

#include <exception>
#include <iostream>
#include <string_view>

namespace canyon::apps {

template <typename Run>
int guarded_main(std::string_view program, int exit_status, Run run, int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << program << ": internal error: " << e.what() << "\n";
    return exit_status;
  }
}

}  // namespace canyon::apps
