// SPDX-License-Identifier: MIT
// Checks figures.json's "stability_map" (tools/vkcloth/figures/stability.cpp).
#pragma once

#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

namespace vkcloth::test {

inline void check_stability_map(const nlohmann::json& m) {
  const auto& s = m.at("stability_map");
  const std::size_t nk = s["k_struct"].size(), nd = s["dt"].size();
  REQUIRE(nk >= 3);
  REQUIRE(nd >= 3);
  for (std::size_t i = 0; i < nk; ++i)
    for (std::size_t j = 0; j < nd; ++j) {
      CAPTURE(i);
      CAPTURE(j);
      CHECK(s["implicit_euler"][i][j].get<bool>()); // implicit Euler: stable on every cell
    }
  // Semi-implicit Euler: unstable on the stiff / large-dt corner, stable on the soft / small-dt one.
  CHECK_FALSE(s["semi_implicit_euler"][nk - 1][nd - 1].get<bool>());
  CHECK_FALSE(s["semi_implicit_euler"][nk - 1][nd - 2].get<bool>());
  CHECK_FALSE(s["semi_implicit_euler"][nk - 2][nd - 1].get<bool>());
  CHECK(s["semi_implicit_euler"][0][0].get<bool>());
  CHECK_FALSE(s["rk4"][nk - 1][nd - 1].get<bool>());
}

} // namespace vkcloth::test
