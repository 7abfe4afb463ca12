// Scene file -> SceneSetup: particles from shapes, materials, conditions, run and output
// settings. Every problem is an InputError naming the file, section and key.
#pragma once

#include "scene/Config.hpp"
#include "scene/SceneSetup.hpp"

namespace tlsph {

// [scene] dimension, checked: 2 or 3.
int sceneDimension(const Config& config);

template <int D>
SceneSetup<D> buildScene(const Config& config);

extern template SceneSetup<2> buildScene<2>(const Config&);
extern template SceneSetup<3> buildScene<3>(const Config&);

}  // namespace tlsph
