# Proves that the estimation core (modules 1-6: core io gnss rtk fusion sim eval), the network module (net) and the
# batch application layer (app) use no DDS middleware:
#  1. no library canyon_<module> links fastrtps, fastcdr, foonathan_memory or canyon_msgs, directly or
#     transitively (LINK_FILE: closures written at configure time by tests/build/NoDds.cmake);
#  2. no header under include/canyon/<module>/ and no source under src/<module>/ includes a Fast DDS / Fast CDR
#     header or a header generated from idl/.
# Usage: cmake -DLINK_FILE=... -DSOURCE_DIR=... -P check_no_dds.cmake
foreach(var LINK_FILE SOURCE_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "check_no_dds: pass -D${var}=...")
  endif()
endforeach()

set(core_modules core io net gnss rtk fusion sim eval app)
set(failures)

# 1. Link closures.
file(STRINGS "${LINK_FILE}" lines)
set(checked_targets)
foreach(line IN LISTS lines)
  if(NOT line MATCHES "^([^:]+): ?(.*)$")
    continue()
  endif()
  set(target "${CMAKE_MATCH_1}")
  string(REPLACE " " ";" links "${CMAKE_MATCH_2}")
  list(APPEND checked_targets ${target})
  foreach(link IN LISTS links)
    get_filename_component(link_name "${link}" NAME)
    if(link_name MATCHES "(fastrtps|fastdds|fastcdr|foonathan_memory|canyon_msgs|canyon::msgs)")
      list(APPEND failures "${target} links ${link}")
    endif()
  endforeach()
endforeach()
if(NOT checked_targets)
  list(APPEND failures "no core module library found in ${LINK_FILE}")
endif()

# 2. Includes. Generated message headers are named after the .idl files.
set(include_pattern "fastdds/|fastrtps/|fastcdr/|fastdds\\.h|fastrtps\\.h|fastcdr\\.h|PubSubTypes\\.h")
file(GLOB idl_files "${SOURCE_DIR}/idl/*.idl")
foreach(idl IN LISTS idl_files)
  get_filename_component(name "${idl}" NAME_WE)
  string(APPEND include_pattern "|[\"</]${name}\\.h[\">]")
endforeach()
set(checked_files 0)
foreach(module IN LISTS core_modules)
  file(GLOB_RECURSE files "${SOURCE_DIR}/include/canyon/${module}/*" "${SOURCE_DIR}/src/${module}/*")
  foreach(file IN LISTS files)
    if(NOT file MATCHES "\\.(h|hh|hpp|hxx|inl|ipp|c|cc|cpp|cxx)$")
      continue()
    endif()
    math(EXPR checked_files "${checked_files} + 1")
    file(STRINGS "${file}" includes REGEX "^[ \t]*#[ \t]*include")
    foreach(include IN LISTS includes)
      if(include MATCHES "${include_pattern}")
        file(RELATIVE_PATH relative "${SOURCE_DIR}" "${file}")
        string(STRIP "${include}" include)
        list(APPEND failures "${relative}: ${include}")
      endif()
    endforeach()
  endforeach()
endforeach()

if(failures)
  list(JOIN failures "\n  " text)
  message(FATAL_ERROR "check_no_dds: the estimation core must not depend on DDS (../shared/DESIGN.md):\n  ${text}")
endif()
list(JOIN checked_targets " " targets_text)
message(STATUS "check_no_dds: OK (${targets_text} link no DDS; ${checked_files} files include no DDS header)")
