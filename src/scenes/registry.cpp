// The built-in scene kinds: a new kind is a folder under src/scenes and a line here.
#include "regolith_twin/run/scene.hpp"

#include "regolith_twin/scenes/impact/impact_scene.hpp"
#include "regolith_twin/scenes/incline/incline_scene.hpp"
#include "regolith_twin/scenes/landing/landing_scene.hpp"
#include "regolith_twin/scenes/plume/plume_scene.hpp"
#include "regolith_twin/scenes/sampler/sampler_scene.hpp"

namespace rt {

std::vector<std::shared_ptr<const SceneKind>> builtin_scene_kinds() {
  return {
      landing_kind(),  // MASCOT landing: `landing:` (docs/scenes.md A)
      sampler_kind(),  // Hayabusa2 sampler shot: `sampler:` (docs/scenes.md B)
      plume_kind(),    // plume erosion in a periodic box: `plume:` (docs/scenes.md D)
      impact_kind(),   // bucket impact of a rigid sphere: `impact:` (docs/scenes.md C.1)
      incline_kind(),  // flow down an inclined plane: `incline:` (docs/scenes.md C.2)
  };
}

}  // namespace rt
