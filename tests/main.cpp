// Catch2 v2 test runner; tests live one concept per file beside this one.
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
