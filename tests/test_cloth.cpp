#include <doctest/doctest.h>
#include "vkcloth/vkcloth.hpp"
using namespace vkcloth;
TEST_CASE("placeholder3") { CHECK(make_chain({}).ok()); }
