// The Catch2 main of every daemon area's test executable (ictus_test_main).
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
