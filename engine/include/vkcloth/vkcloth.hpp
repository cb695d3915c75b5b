// SPDX-License-Identifier: MIT
// Umbrella header of the vkcloth library.
#pragma once

#include "vkcloth/builders.hpp"
#include "vkcloth/collider_mesh.hpp"
#include "vkcloth/material.hpp"
#include "vkcloth/cpu_solver.hpp"
#include "vkcloth/cpu_world.hpp"
#include "vkcloth/measure.hpp"
#include "vkcloth/params.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/system.hpp"
#include "vkcloth/topology.hpp"
#include "vkcloth/world_types.hpp"
#include "vkcloth/scene.hpp"
#include "vkcloth/gpu/backend_choice.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"
#include "vkcloth/gpu/world.hpp"
