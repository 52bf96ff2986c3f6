#include "render/animation_loop.h"

#include "core/stopwatch.h"

namespace hprt {

void run_animation(Scene& scene, const SceneAnimator& animator, Intersector& backend,
                   const AnimationRange& range, const RenderFrameFn& render,
                   const FrameDoneFn& on_frame) {
  for (int k = range.first; k < range.end; ++k) {
    AnimationFrame f;
    f.frame = k;
    auto start = Clock::now();
    animator.apply(k, scene);
    f.animate_ms = ms_since(start);
    start = Clock::now();
    if (k == range.first)
      backend.build(scene);
    else
      backend.update(scene);
    f.update_ms = ms_since(start);
    f.info = backend.info();
    if (k == range.first) f.info.rebuilt = true;  // the first frame's build counts as its update
    if (k != range.first || range.render_first) {
      f.render_ms = render(k, f.stats);
      f.rendered = true;
    }
    on_frame(f);
  }
}

}  // namespace hprt
