# The libraries the fuzz targets explore (tests/fuzz): built with libFuzzer's
# coverage instrumentation when BSLS_FUZZ is on, and the fuzz programs.
set(BSLS_FUZZ_COVERAGE bsls_decoder bsls_extraction bsls_interpretation bsls_pattern
    decoder_fuzz bsls_capture_service bsls_slides capture_service_fuzz)

# Common compile settings for every BSLS target.
function(bsls_target_defaults target)
  target_compile_features(${target} PUBLIC cxx_std_20)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow
                                           -Wno-missing-field-initializers)
  if(BSLS_FUZZ AND target IN_LIST BSLS_FUZZ_COVERAGE)
    # libFuzzer's coverage only where the fuzz targets search (it slows every
    # comparison: everywhere else it would only slow the sanitizer tests).
    target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link)
  endif()
  if(BSLS_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=${BSLS_SANITIZE}
                                             -fno-omit-frame-pointer -fno-sanitize-recover=all)
    target_link_options(${target} PRIVATE -fsanitize=${BSLS_SANITIZE})
  endif()
endfunction()

# bsls_library(NAME ALIAS SOURCES ... DEPS ...): a static library with a
# public include/ folder beside the CMakeLists that calls it.
function(bsls_library name)
  cmake_parse_arguments(ARG "" "ALIAS" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  add_library(${ARG_ALIAS} ALIAS ${name})
  target_include_directories(${name} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(${name} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  bsls_target_defaults(${name})
endfunction()
