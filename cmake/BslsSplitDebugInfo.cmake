# Install time: splits the debug information off one installed program.
# Included by the install(CODE) rule of bsls_install_program
# (cmake/BslsInstall.cmake), inside cmake_install.cmake, after the program
# was copied. A RelWithDebInfo `bsls` is ~250 MB, almost all of it DWARF; the
# installed program keeps only what it runs with.
#
# In:  BSLS_SPLIT_FILE      the program, relative to the prefix (sbin/bslsd)
#      BSLS_SPLIT_DEBUGDIR  the debug folder, relative to the prefix (lib/debug)
#      BSLS_SPLIT_OBJCOPY, BSLS_SPLIT_READELF  binutils (CMAKE_OBJCOPY, CMAKE_READELF)
#      CMAKE_INSTALL_PREFIX and $ENV{DESTDIR} of this install
# Out, for prefix P and debug folder D (paths as on the installed machine;
# under $DESTDIR when it is set):
#      P/D/P/sbin/bslsd.debug  the DWARF (objcopy --only-keep-debug, zlib-
#          compressed sections) at the path GDB derives from the program's
#          own path and its debug-file-directory P/D: with P = /usr that is
#          /usr/lib/debug/usr/sbin/bslsd.debug, GDB's default directory and
#          Debian's layout, so GDB finds it without being told
#      P/D/.build-id/NN/REST.debug  a relative link to it, named by the
#          program's GNU build id (how GDB, systemd-coredump and elfutils
#          look first); links of earlier installs to the same file are removed
#      P/sbin/bslsd  stripped of debug sections and unneeded symbols, with a
#          .gnu_debuglink section naming bslsd.debug and its CRC-32
# A program without .debug_info (`cmake --install --strip`, a build without
# -g) is left as it is, and any debug file of an earlier install with it.

function(bsls_split_debug_info)
  set(prefix "${CMAKE_INSTALL_PREFIX}")
  cmake_path(ABSOLUTE_PATH prefix NORMALIZE)
  string(REGEX REPLACE "(.)/$" "\\1" prefix "${prefix}")
  set(program "${prefix}/${BSLS_SPLIT_FILE}")
  cmake_path(GET program PARENT_PATH program_dir)
  cmake_path(GET program FILENAME name)
  set(debug_root "${prefix}/${BSLS_SPLIT_DEBUGDIR}")
  set(debug_file "${debug_root}${program_dir}/${name}.debug")
  # Where the files are now: under DESTDIR when staging (packaging).
  set(staged "$ENV{DESTDIR}${program}")
  set(staged_debug "$ENV{DESTDIR}${debug_file}")

  if(NOT EXISTS "${staged}")
    message(FATAL_ERROR "Splitting debug information: ${staged} was not installed")
  endif()
  if(NOT BSLS_SPLIT_OBJCOPY OR NOT BSLS_SPLIT_READELF)
    message(WARNING "Splitting debug information: objcopy or readelf was not found when the "
                    "build was configured; ${program} is installed with its debug information")
    return()
  endif()

  execute_process(COMMAND "${BSLS_SPLIT_READELF}" --wide --section-headers --notes "${staged}"
                  OUTPUT_VARIABLE elf RESULT_VARIABLE failed ERROR_VARIABLE error)
  if(failed)
    message(FATAL_ERROR "Splitting debug information: readelf ${staged}: ${error}")
  endif()
  if(NOT elf MATCHES "[ \t]\\.debug_info[ \t]")
    message(STATUS "No debug information in ${program} (stripped or built without -g): "
                   "nothing to split")
    return()
  endif()
  set(build_id "")
  if(elf MATCHES "Build ID: ([0-9a-f]+)")
    set(build_id "${CMAKE_MATCH_1}")
  endif()

  cmake_path(GET staged_debug PARENT_PATH staged_debug_dir)
  file(MAKE_DIRECTORY "${staged_debug_dir}")
  # 1. The debug sections alone, compressed (about a third of their size;
  #    GDB, readelf and elfutils read them as they are).
  execute_process(COMMAND "${BSLS_SPLIT_OBJCOPY}" --only-keep-debug
                          --compress-debug-sections=zlib "${staged}" "${staged_debug}"
                  RESULT_VARIABLE failed ERROR_VARIABLE error)
  if(failed)
    message(FATAL_ERROR "Splitting debug information: objcopy --only-keep-debug ${staged}: ${error}")
  endif()
  file(CHMOD "${staged_debug}" PERMISSIONS OWNER_READ OWNER_WRITE GROUP_READ WORLD_READ)
  # 2. The program without them, linked to the file by name and CRC-32 (the
  #    CRC is of the file written in step 1, so the link is added after it).
  execute_process(COMMAND "${BSLS_SPLIT_OBJCOPY}" --strip-debug --strip-unneeded
                          "--add-gnu-debuglink=${staged_debug}" "${staged}"
                  RESULT_VARIABLE failed ERROR_VARIABLE error)
  if(failed)
    message(FATAL_ERROR "Splitting debug information: objcopy --strip-debug ${staged}: ${error}")
  endif()
  set(installed "${debug_file}")

  # 3. The build-id link; links left by earlier installs of this program
  #    (other build ids) would point at a file that no longer matches them.
  if(build_id MATCHES "^(..)(.+)$")
    set(link_name "${debug_root}/.build-id/${CMAKE_MATCH_1}/${CMAKE_MATCH_2}.debug")
    set(link "$ENV{DESTDIR}${link_name}")
    cmake_path(GET link PARENT_PATH link_dir)
    file(GLOB old_links LIST_DIRECTORIES false "$ENV{DESTDIR}${debug_root}/.build-id/*/*.debug")
    foreach(old IN LISTS old_links)
      if(IS_SYMLINK "${old}")
        file(REAL_PATH "${old}" target)
        file(REAL_PATH "${staged_debug}" current)
        if(target STREQUAL current)
          file(REMOVE "${old}")
        endif()
      endif()
    endforeach()
    file(MAKE_DIRECTORY "${link_dir}")
    file(RELATIVE_PATH relative "${link_dir}" "${staged_debug}")
    file(CREATE_LINK "${relative}" "${link}" SYMBOLIC)
    list(APPEND installed "${link_name}")
  endif()

  # install_manifest*.txt lists them with the other files (as CMake does,
  # without DESTDIR).
  set(CMAKE_INSTALL_MANIFEST_FILES ${CMAKE_INSTALL_MANIFEST_FILES} ${installed} PARENT_SCOPE)
  set(hint "")
  if(NOT debug_root STREQUAL "/usr/lib/debug")
    set(hint "; gdb finds it with: set debug-file-directory ${debug_root}")
  endif()
  if(DEFINED ENV{DESTDIR} AND NOT "$ENV{DESTDIR}" STREQUAL "")
    string(APPEND hint " (staged under $ENV{DESTDIR})")
  endif()
  message(STATUS "Stripped ${program}; its debug information is in ${debug_file}"
                 " (build id ${build_id})${hint}")
endfunction()

bsls_split_debug_info()
