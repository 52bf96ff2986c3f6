// Image tiles scheduled dynamically over oneTBB workers: one task per tile
// (grain 1, simple_partitioner), so a cheap tile never waits on an expensive
// one. Tile order and tile contents do not depend on the thread count.
#pragma once

#include <functional>
#include <vector>

namespace hprt {

struct Tile {
  int x0 = 0, y0 = 0;  // top-left pixel
  int x1 = 0, y1 = 0;  // one past the bottom-right pixel
  int pixel_count() const { return (x1 - x0) * (y1 - y0); }
};

// Row-major tiles of at most `size` x `size` pixels covering width x height.
std::vector<Tile> make_tiles(int width, int height, int size);

// Calls fn(tile) for every tile in parallel in the caller's task arena; one
// call per tile task (a std::function call per tile, never per pixel).
void for_each_tile(const std::vector<Tile>& tiles, const std::function<void(const Tile&)>& fn);

}  // namespace hprt
