# Installing programs: stripped, with their debug information in a separate
# file that GDB finds (docs/deployment.md, "Debug information").

set(BSLS_SPLIT_DEBUG_INFO_SCRIPT "${CMAKE_CURRENT_LIST_DIR}/BslsSplitDebugInfo.cmake")

# bsls_install_program(TARGET DESTINATION <folder relative to the prefix>):
# installs an executable or shared-library target in the install component
# of its own name (`cmake --install BUILD --component bslsd`), then, at
# install time, moves its debug information into
# <prefix>/${BSLS_INSTALL_DEBUGDIR}<prefix>/<folder>/<file>.debug and strips
# the installed file (cmake/BslsSplitDebugInfo.cmake says how and why).
function(bsls_install_program target)
  cmake_parse_arguments(ARG "" "DESTINATION" "" ${ARGN})
  if(NOT ARG_DESTINATION OR IS_ABSOLUTE "${ARG_DESTINATION}")
    message(FATAL_ERROR "bsls_install_program(${target}): DESTINATION must be a folder "
                        "relative to the prefix, so that --prefix and DESTDIR move it")
  endif()
  install(TARGETS ${target}
          RUNTIME DESTINATION ${ARG_DESTINATION} COMPONENT ${target}
          LIBRARY DESTINATION ${ARG_DESTINATION} COMPONENT ${target})
  # Runs after the copy above (install rules run in order): the file is in
  # place, with its RPATH already rewritten by CMake.
  install(CODE "
    set(BSLS_SPLIT_FILE \"${ARG_DESTINATION}/$<TARGET_FILE_NAME:${target}>\")
    set(BSLS_SPLIT_DEBUGDIR \"${BSLS_INSTALL_DEBUGDIR}\")
    set(BSLS_SPLIT_OBJCOPY \"${CMAKE_OBJCOPY}\")
    set(BSLS_SPLIT_READELF \"${CMAKE_READELF}\")
    include(\"${BSLS_SPLIT_DEBUG_INFO_SCRIPT}\")"
    COMPONENT ${target})
endfunction()
