# The layering of the tree, checked on every configure: what the contracts
# and the capture daemon may link, transitively. A target that breaks a
# rule fails the configure (CMake generates nothing), each breach named with
# the chain that brought it in, e.g. "bslsd -> bslsd_core -> bsls_calibration".
#
#  - The contracts' libraries (every target of proto/: bsls_proto, bsls_rpc)
#    link bsls::common alone of this project (targets of common/ and proto/,
#    not bsls::config): no OpenCV, no yaml-cpp, no processing or daemon
#    library. The messages' conversions to each side's own types live with
#    that side (processing/contract, daemon/service's contract_messages).
#  - bslsd links no processing library (targets of processing/), except
#      bsls_pattern, bsls_geometry      the simulated backend renders the
#                                       slides through a pinhole camera
#                                       (bsls::simulator_scene);
#      bsls_calibration_header          a calibration file's side;
#      bsls_processing_client           the client of bsls-processd.
#
# An item is a project target when its SOURCE_DIR is in the source tree;
# OpenCV and yaml-cpp are recognised by their imported targets' names and by
# library file names.

# The targets and libraries `target` links, transitively, in `out_var`; the
# variable _bsls_via_<item as a C identifier> names the item that brought
# each one in.
function(_bsls_link_closure target out_var)
  set(seen "")
  set(queue "${target}")
  set(assigned "${target}")
  string(MAKE_C_IDENTIFIER "${target}" key)
  set(_bsls_via_${key} "" PARENT_SCOPE)
  while(queue)
    list(POP_FRONT queue item)
    if(item IN_LIST seen)
      continue()
    endif()
    list(APPEND seen "${item}")
    if(NOT TARGET "${item}")
      continue()
    endif()
    get_target_property(type "${item}" TYPE)
    get_target_property(imported "${item}" IMPORTED)
    set(deps "")
    if(NOT imported AND NOT type STREQUAL "INTERFACE_LIBRARY")
      get_target_property(direct "${item}" LINK_LIBRARIES)
      if(direct)
        list(APPEND deps ${direct})
      endif()
    endif()
    get_target_property(interface "${item}" INTERFACE_LINK_LIBRARIES)
    if(interface)
      list(APPEND deps ${interface})
    endif()
    foreach(dep IN LISTS deps)
      # $<LINK_ONLY:x> (a static library's private dependency) is x; of any
      # other generator expression the names in it are kept.
      string(REGEX REPLACE "\\$<LINK_ONLY:([^>]*)>" "\\1" dep "${dep}")
      if(dep MATCHES "\\$<")
        string(REGEX REPLACE "\\$<[^:>]*:?" ";" dep "${dep}")
        string(REPLACE ">" ";" dep "${dep}")
        string(REPLACE "," ";" dep "${dep}")
      endif()
      foreach(name IN LISTS dep)
        if(name STREQUAL "" OR name MATCHES "^-" OR name IN_LIST seen)
          continue()
        endif()
        if(TARGET "${name}")
          get_target_property(aliased "${name}" ALIASED_TARGET)
          if(aliased)
            set(name "${aliased}")
          endif()
        endif()
        if(NOT name IN_LIST assigned)
          list(APPEND assigned "${name}")
          string(MAKE_C_IDENTIFIER "${name}" key)
          set(_bsls_via_${key} "${item}" PARENT_SCOPE)
        endif()
        list(APPEND queue "${name}")
      endforeach()
    endforeach()
  endwhile()
  list(REMOVE_ITEM seen "${target}")
  set(${out_var} "${seen}" PARENT_SCOPE)
endfunction()

# "a -> b -> c": how `target` came to link `item`.
function(_bsls_link_chain target item out_var)
  set(chain "${item}")
  set(at "${item}")
  foreach(step RANGE 100)
    string(MAKE_C_IDENTIFIER "${at}" key)
    if(at STREQUAL target OR "${_bsls_via_${key}}" STREQUAL "")
      break()
    endif()
    set(at "${_bsls_via_${key}}")
    set(chain "${at} -> ${chain}")
  endforeach()
  set(${out_var} "${chain}" PARENT_SCOPE)
endfunction()

# The folder of the source tree (e.g. "processing") a project target was
# defined in, or "" for anything else.
function(_bsls_part_of item out_var)
  set(part "")
  if(TARGET "${item}")
    get_target_property(imported "${item}" IMPORTED)
    if(NOT imported)
      get_target_property(dir "${item}" SOURCE_DIR)
      file(RELATIVE_PATH rel "${PROJECT_SOURCE_DIR}" "${dir}")
      string(REGEX REPLACE "/.*" "" part "${rel}")
      if(rel MATCHES "^common/config")
        set(part "common/config")
      endif()
    endif()
  endif()
  set(${out_var} "${part}" PARENT_SCOPE)
endfunction()

# Fails the configure (SEND_ERROR) when a present target of `targets` links something
# `rule` forbids: "contracts" or "daemon" (see above).
function(bsls_check_layering rule)
  set(targets ${ARGN})
  set(problems "")
  foreach(target IN LISTS targets)
    if(NOT TARGET "${target}")
      continue()
    endif()
    _bsls_link_closure("${target}" closure)
    foreach(item IN LISTS closure)
      _bsls_part_of("${item}" part)
      set(bad "")
      if(item MATCHES "(^|[/:_])(opencv|libopencv)" OR item MATCHES "yaml-cpp|YAML_CPP")
        if(rule STREQUAL "contracts")
          set(bad "OpenCV or yaml-cpp")
        endif()
      endif()
      if(rule STREQUAL "contracts" AND NOT part STREQUAL ""
         AND NOT part STREQUAL "common" AND NOT part STREQUAL "proto")
        set(bad "a library of ${part}/")
      endif()
      if(rule STREQUAL "daemon" AND part STREQUAL "processing"
         AND NOT item MATCHES "^bsls_(pattern|geometry|calibration_header|processing_client)$")
        set(bad "a processing library")
      endif()
      if(bad)
        _bsls_link_chain("${target}" "${item}" chain)
        string(APPEND problems "\n  ${target} links ${bad}: ${chain}")
      endif()
    endforeach()
  endforeach()
  if(problems)
    message(SEND_ERROR "Layering (cmake/BslsLayering.cmake) broken:${problems}")
  endif()
endfunction()
