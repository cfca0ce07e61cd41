// Reads a scene description (YAML, see README.md: sky, light, textures, objects) into a Scene.
#pragma once

#include <memory>

#include "livo/config.hpp"
#include "livo/sim/scene.hpp"

namespace livo::sim {

/// Builds (and build()s) the scene described by `scene`; every key must be known. Errors are
/// ConfigErrors naming the file and key.
std::unique_ptr<Scene> readScene(const Config& scene);

}  // namespace livo::sim
