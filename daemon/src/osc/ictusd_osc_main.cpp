// ictusd-osc -- the run and render verbs on their own (the tests use it; the
// same functions are ictusd's verbs once main.cpp dispatches to them).
#include "ictus/verbs_osc.hpp"

#include <cstring>
#include <iostream>

int main(int argc, char **argv)
{
    if (argc >= 2 && std::strcmp(argv[1], "run") == 0)
        return ictus::cmd_run(argc - 1, argv + 1);
    if (argc >= 2 && std::strcmp(argv[1], "render") == 0)
        return ictus::cmd_render(argc - 1, argv + 1);
    std::cerr << "usage: ictusd-osc run|render [options] (see ictusd-osc run --help)\n";
    return 2;
}
