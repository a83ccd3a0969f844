// realtime.hpp -- real-time scheduling for the threads that keep time in
// `ictusd run` (the physics loop, the strike sender), as audio software does
// (Pd -rt, JACK): under SCHED_FIFO a busy machine's ordinary processes no
// longer delay a physics step or a strike. The kernel's RT throttling
// (sched_rt_runtime_us) still leaves the rest of the machine its share.
#pragma once

#include <string>

namespace ictus
{

// Puts the calling thread under SCHED_FIFO at `priority` (1..99). False with
// the reason (e.g. "Operation not permitted": no root, no rtprio limit) when
// the system refuses; the thread then keeps its ordinary scheduling.
bool set_realtime_priority(int priority, std::string *why = nullptr);

// The priorities ictusd uses: the strike sender above the physics loop (a
// strike ready to go must not wait for a step), both below the kernel's own
// real-time threads (99) and JACK's usual 70-80.
constexpr int kPhysicsPriority = 60;
constexpr int kStrikeSenderPriority = 65;

} // namespace ictus
