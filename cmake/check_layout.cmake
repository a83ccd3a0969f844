# check_layout.cmake -- the layout rules of ictus (docs/architecture.md), as a
# build step: `cmake -DICTUS_ROOT=<source tree> -P check_layout.cmake` exits
# with an error naming every file that breaks one.
#
# Daemon: areas in the order of the chain; a file of an area may include the
# headers of its own area and of the areas listed for it below (all before it
# in the chain, never after):
#   base mocap character control sim gesture score perform net cli
# ODE (<ode/...>) only in src/sim, liblo (<lo/...>) only in src/net: control
# never sees ODE, sim and perform never see liblo. Every public header lives in
# include/ictus/<area>/, every source (and private header) in src/<area>/.
# Externals: the DSP core (externals/core) never includes Pd (m_pd.h) nor a
# wrapper; the membrane (and its mode table, Bessel zeros) never includes the
# contact (contact -> membrane, one way).
if(NOT ICTUS_ROOT)
  message(FATAL_ERROR "check_layout: -DICTUS_ROOT=<source tree> is required")
endif()

set(areas base mocap character control sim gesture score perform net cli)
# What each area may include besides itself (docs/architecture.md).
set(allow_base "")
set(allow_mocap base)
set(allow_character base mocap)
set(allow_control base mocap character)
set(allow_sim base mocap character control)
set(allow_gesture base mocap character)
set(allow_score base mocap character gesture)
set(allow_perform base mocap character control sim gesture score)
set(allow_net base mocap character control sim gesture score perform)
set(allow_cli base mocap character control sim gesture score perform net)
set(errors "")

# The includes of a file: a list of "LINE|TARGET" ("ictus/sim/scene.hpp", "<ode/ode.h>").
function(file_includes path out)
  file(STRINGS "${path}" lines)
  set(found "")
  set(n 0)
  foreach(line IN LISTS lines)
    math(EXPR n "${n} + 1")
    if(line MATCHES "^[ \t]*#[ \t]*include[ \t]*([<\"][^>\"]+[>\"])")
      list(APPEND found "${n}|${CMAKE_MATCH_1}")
    endif()
  endforeach()
  set(${out} "${found}" PARENT_SCOPE)
endfunction()

# One of file_includes' entries: sets `target` and `where` ("FILE:LINE") in the caller.
macro(read_include entry file)
  string(REPLACE "|" ";" parts "${entry}")
  list(GET parts 0 line)
  list(GET parts 1 target)
  set(where "${file}:${line}")
endmacro()

# ---- daemon ----------------------------------------------------------------
set(daemon "${ICTUS_ROOT}/daemon")
file(GLOB_RECURSE daemon_files RELATIVE "${daemon}"
     "${daemon}/include/*" "${daemon}/src/*")
foreach(rel IN LISTS daemon_files)
  if(rel MATCHES "CMakeLists.txt$")
    continue()
  endif()
  if(rel MATCHES "^include/ictus/([a-z_]+)/[^/]+$")
    set(area "${CMAKE_MATCH_1}")
    set(is_source FALSE)
  elseif(rel MATCHES "^src/([a-z_]+)/[^/]+$")
    set(area "${CMAKE_MATCH_1}")
    set(is_source TRUE)
  else()
    list(APPEND errors "daemon/${rel}: not in an area (public headers go in include/ictus/<area>/, sources in src/<area>/)")
    continue()
  endif()
  list(FIND areas "${area}" rank)
  if(rank LESS 0)
    list(APPEND errors "daemon/${rel}: '${area}' is not an area (${areas})")
    continue()
  endif()
  file_includes("${daemon}/${rel}" includes)
  foreach(entry IN LISTS includes)
    read_include("${entry}" "daemon/${rel}")
    if(target MATCHES "^[<\"]ictus/([a-z_]+)/")
      set(to "${CMAKE_MATCH_1}")
      list(FIND areas "${to}" to_rank)
      list(FIND allow_${area} "${to}" allowed)
      if(to_rank LESS 0)
        list(APPEND errors "${where}: includes ${target}: '${to}' is not an area")
      elseif(NOT to STREQUAL area AND allowed LESS 0)
        string(REPLACE ";" ", " may "${allow_${area}}")
        list(APPEND errors "${where}: ${area} includes ${target}: ${area} may include only ${may} (includes go one way down the chain)")
      endif()
    elseif(target MATCHES "^[<\"]ictus/[^/]+$")
      list(APPEND errors "${where}: includes ${target}: headers are under ictus/<area>/")
    elseif(target MATCHES "^[<\"]ode/")
      if(NOT (area STREQUAL "sim" AND is_source))
        list(APPEND errors "${where}: ${area} includes ${target}: only sim's sources see ODE")
      endif()
    elseif(target MATCHES "^[<\"]lo/")
      if(NOT (area STREQUAL "net" AND is_source))
        list(APPEND errors "${where}: ${area} includes ${target}: only net's sources see liblo")
      endif()
    elseif(target MATCHES "m_pd\\.h")
      list(APPEND errors "${where}: includes ${target}: the daemon never sees Pd")
    endif()
  endforeach()
endforeach()

# ---- externals ---------------------------------------------------------------
set(core "${ICTUS_ROOT}/externals/core")
file(GLOB core_files RELATIVE "${core}" "${core}/*.c" "${core}/*.h" "${core}/*.inc")
foreach(rel IN LISTS core_files)
  file_includes("${core}/${rel}" includes)
  foreach(entry IN LISTS includes)
    read_include("${entry}" "externals/core/${rel}")
    if(target MATCHES "m_pd\\.h|g_canvas\\.h|s_stuff\\.h")
      list(APPEND errors "${where}: includes ${target}: the DSP core never sees Pd")
    elseif(target MATCHES "^\"\\.\\./|^\"pd/|ictus_pd")
      list(APPEND errors "${where}: includes ${target}: the core never includes a Pd wrapper")
    elseif(rel MATCHES "^(membrane|mode_table|bessel)" AND target MATCHES "contact")
      list(APPEND errors "${where}: includes ${target}: contact depends on membrane, never the reverse")
    endif()
  endforeach()
endforeach()

list(LENGTH errors n_errors)
if(n_errors GREATER 0)
  string(REPLACE ";" "\n  " text "${errors}")
  message(FATAL_ERROR "layout rules broken (docs/architecture.md):\n  ${text}")
endif()
