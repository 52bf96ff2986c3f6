// Tile enumeration and dynamic tile scheduling (tbb::parallel_for, grain 1).
#include "render/tile_scheduler.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>

namespace hprt {

std::vector<Tile> make_tiles(int width, int height, int size) {
  std::vector<Tile> tiles;
  if (width <= 0 || height <= 0 || size <= 0) return tiles;
  for (int y = 0; y < height; y += size)
    for (int x = 0; x < width; x += size)
      tiles.push_back({x, y, std::min(x + size, width), std::min(y + size, height)});
  return tiles;
}

void for_each_tile(const std::vector<Tile>& tiles, const std::function<void(const Tile&)>& fn) {
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, tiles.size(), 1),
      [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) fn(tiles[i]);
      },
      tbb::simple_partitioner());
}

}  // namespace hprt
