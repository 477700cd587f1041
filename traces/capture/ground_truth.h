// The ground truth of visibility (docs/architecture.md, "Definitions"): every object of `order`
// drawn, nothing culled, into the target's ID buffer with a cleared depth buffer, in that order (so
// that ties at equal depth resolve as in the technique's frame); an object is visible iff one pixel
// shows it. Its fragment counts go to a scratch counter slot and are not recorded.
#pragma once

#include <glm/mat4x4.hpp>

#include <cstdint>
#include <vector>

#include "model/scene/frame.h"
#include "traces/capture/draw_recorder.h"
#include "traces/capture/render_target.h"
#include "traces/capture/scene_pass.h"

namespace nbsim::capture {

scene::GroundTruth ground_truth(const ScenePass& pass, const RenderTarget& target, DrawRecorder& recorder,
                                const glm::mat4& view_proj, bool reversed, const std::vector<std::uint32_t>& order);

}  // namespace nbsim::capture
