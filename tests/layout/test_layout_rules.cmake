# test_layout_rules.cmake -- proves that cmake/check_layout.cmake fails the
# build for each broken rule (run by CTest as layout_rules).
set(checker "${ICTUS_ROOT}/cmake/check_layout.cmake")
set(failures 0)

# check(NAME EXPECT pass|fail MESSAGE text FILES path content [path content ...])
function(check name expect message)
  set(root "${SCRATCH}/${name}")
  file(REMOVE_RECURSE "${root}")
  file(MAKE_DIRECTORY "${root}/daemon/include/ictus" "${root}/daemon/src" "${root}/externals/core")
  set(files ${ARGN})
  list(LENGTH files n)
  math(EXPR last "${n} - 1")
  foreach(i RANGE 0 ${last} 2)
    math(EXPR j "${i} + 1")
    list(GET files ${i} path)
    list(GET files ${j} content)
    file(WRITE "${root}/${path}" "${content}\n")
  endforeach()
  execute_process(COMMAND ${CMAKE_COMMAND} -DICTUS_ROOT=${root} -P ${checker}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  set(ok FALSE)
  if(expect STREQUAL "pass" AND rc EQUAL 0)
    set(ok TRUE)
  elseif(expect STREQUAL "fail" AND NOT rc EQUAL 0)
    string(FIND "${err}" "${message}" at)
    if(at GREATER -1)
      set(ok TRUE)
    endif()
  endif()
  if(ok)
    message(STATUS "ok: ${name} (${expect})")
  else()
    message(SEND_ERROR "FAILED: ${name}: expected ${expect} with '${message}', got rc=${rc}\n${err}")
  endif()
endfunction()

# Each rule broken once.
check(control_sees_sim fail "control includes \"ictus/sim/scene.hpp\": control may include only base, mocap, character"
      daemon/src/control/ik.cpp "#include \"ictus/sim/scene.hpp\"")
check(control_sees_ode fail "only sim's sources see ODE"
      daemon/src/control/ik.cpp "#include <ode/ode.h>")
check(sim_header_sees_ode fail "only sim's sources see ODE"
      daemon/include/ictus/sim/scene.hpp "#include <ode/ode.h>")
check(sim_sees_liblo fail "only net's sources see liblo"
      daemon/src/sim/scene.cpp "#include <lo/lo.h>")
check(perform_sees_liblo fail "only net's sources see liblo"
      daemon/src/perform/loop.cpp "#  include <lo/lo_lowlevel.h>")
check(perform_sees_net fail "perform includes \"ictus/net/osc_sender.hpp\": perform may include only"
      daemon/include/ictus/perform/performance.hpp "#include \"ictus/net/osc_sender.hpp\"")
check(mocap_sees_character fail "mocap may include only base"
      daemon/src/mocap/bvh.cpp "#include \"ictus/character/character.hpp\"")
check(gesture_sees_score fail "gesture may include only base, mocap, character"
      daemon/src/gesture/segment.cpp "#include \"ictus/score/score.hpp\"")
check(gesture_sees_sim fail "gesture may include only base, mocap, character"
      daemon/src/gesture/segment.cpp "#include \"ictus/sim/scene.hpp\"")
check(score_sees_control fail "score may include only base, mocap, character, gesture"
      daemon/include/ictus/score/gesture_score.hpp "#include \"ictus/control/kinematic_chain.hpp\"")
check(flat_header fail "not in an area"
      daemon/include/ictus/strike.hpp "#pragma once")
check(unknown_area fail "is not an area"
      daemon/src/osc/verbs.cpp "int x;")
check(core_sees_pd fail "the DSP core never sees Pd"
      externals/core/membrane.c "#include \"m_pd.h\"")
check(core_sees_wrapper fail "the core never includes a Pd wrapper"
      externals/core/contact.c "#include \"../pd/ictus_pd.h\"")
check(membrane_sees_contact fail "contact depends on membrane, never the reverse"
      externals/core/membrane_internal.h "#include \"contact.h\"")
# The same includes, in the areas allowed to have them.
check(allowed pass ""
      daemon/src/sim/scene.cpp "#include <ode/ode.h>\n#include \"ictus/control/kinematic_chain.hpp\""
      daemon/src/net/osc_sender.cpp "#include <lo/lo.h>\n#include \"ictus/perform/commands.hpp\""
      daemon/src/cli/main.cpp "#include \"ictus/net/osc_sender.hpp\"\n#include \"ictus/base/rotation.hpp\""
      daemon/src/score/plan.cpp "#include \"ictus/gesture/gesture.hpp\""
      daemon/src/mocap/text_lines.hpp "#include \"ictus/base/rotation.hpp\""
      externals/core/contact.c "#include \"membrane.h\"\n#include \"contact.h\"")

# The real tree keeps every rule.
execute_process(COMMAND ${CMAKE_COMMAND} -DICTUS_ROOT=${ICTUS_ROOT} -P ${checker}
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(SEND_ERROR "FAILED: the source tree breaks the layout rules:\n${err}")
else()
  message(STATUS "ok: the source tree keeps the layout rules")
endif()
