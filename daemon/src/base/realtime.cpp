// Real-time scheduling of the calling thread (realtime.hpp).
#include "ictus/base/realtime.hpp"

#include <pthread.h>
#include <sched.h>

#include <cstring>

namespace ictus
{

bool set_realtime_priority(int priority, std::string *why)
{
    sched_param param{};
    param.sched_priority = priority;
    const int error = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
    if (error != 0 && why)
        *why = std::strerror(error);
    return error == 0;
}

} // namespace ictus
