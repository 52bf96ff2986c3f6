// The animate -> update -> render loop over a range of an animation's frames,
// shared by `hprt render --frames` and `hprt bench frames`: frame `first`
// animated and built from scratch, each later frame animated in place and
// brought up to date with Intersector::update() (its strategy is the
// backend's), then rendered by the caller's function.
#pragma once

#include <functional>

#include "anim/scene_animator.h"
#include "backends/intersector.h"
#include "render/whitted.h"

namespace hprt {

struct AnimationFrame {
  int frame = 0;
  double animate_ms = 0.0;  // the deformers (SceneAnimator::apply)
  double update_ms = 0.0;   // build() for the first frame, update() for the others
  BuildInfo info;           // the backend's after it; info.rebuilt is true for the first frame
  bool rendered = false;
  double render_ms = 0.0;  // as the render function reports it
  RenderStats stats;
};

// Renders frame k: `scene` holds frame k and the backend is up to date.
// Returns the render time in ms (what the caller counts as rendering) and
// fills `stats`.
using RenderFrameFn = std::function<double(int frame, RenderStats& stats)>;
using FrameDoneFn = std::function<void(const AnimationFrame&)>;

struct AnimationRange {
  int first = 0;
  int end = 1;               // frames first .. end-1
  bool render_first = true;  // false: the first frame is only built (a benchmark's warm-up)
};

// Runs the loop in the caller's task arena (run_with_threads). `animator`
// was made from `scene`; `on_frame` is called after each frame.
void run_animation(Scene& scene, const SceneAnimator& animator, Intersector& backend,
                   const AnimationRange& range, const RenderFrameFn& render,
                   const FrameDoneFn& on_frame);

}  // namespace hprt
