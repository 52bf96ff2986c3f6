#!/usr/bin/env bash
# The examples against an installed hprt only: installs BUILD to a temporary
# prefix, checks that the installed headers include nothing that is not
# installed, configures and builds examples/consumer, examples/plugin_bvh and
# examples/plugin_bruteforce_c with CMAKE_PREFIX_PATH=prefix, and runs them:
# the consumer's diff passes, `hprt validate rays` finds the bvh and
# brute-force plugins correct and the broken one wrong, and `hprt bench trace`
# runs a plugin beside Embree. Usage: test_examples.sh BUILD_DIR
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
build="$(cd "${1:?usage: test_examples.sh BUILD_DIR}" && pwd)"
work="$(mktemp -d /tmp/hprt-examples.XXXXXX)"
trap 'rm -rf "$work"' EXIT
prefix="$work/prefix"
gen=()
command -v ninja > /dev/null && gen=(-G Ninja)

cmake --install "$build" --prefix "$prefix" > "$work/install.log"
for f in bin/hprt include/hprt/hprt.h include/hprt/plugin.h lib/cmake/hprt/hprtConfig.cmake \
         lib/cmake/hprt/hprtConfigVersion.cmake lib/pkgconfig/hprt.pc; do
  [[ -e "$prefix/$f" ]] || { echo "test_examples: $f not installed" >&2; exit 1; }
done
# The public headers compile alone, with nothing but the prefix on the include path.
for h in hprt.h plugin.h; do
  echo "#include <hprt/$h>" | g++ -std=c++20 -fsyntax-only -nostdinc++ -isystem /usr/include/c++/12 \
    -isystem /usr/include/x86_64-linux-gnu/c++/12 -I"$prefix/include" -x c++ - ||
    { echo "test_examples: <hprt/$h> needs more than the installed headers" >&2; exit 1; }
done
echo '#include <hprt/plugin.h>' | gcc -std=c99 -fsyntax-only -I"$prefix/include" -x c - ||
  { echo "test_examples: <hprt/plugin.h> is not plain C" >&2; exit 1; }
# pkg-config finds the relocated prefix.
PKG_CONFIG_PATH="$prefix/lib/pkgconfig" pkg-config --cflags --libs hprt | grep -q -- "-L$prefix/lib" ||
  { echo "test_examples: hprt.pc does not point at the prefix" >&2; exit 1; }

for ex in consumer plugin_bvh plugin_bruteforce_c; do
  cmake -S "$repo/examples/$ex" -B "$work/$ex" "${gen[@]}" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_PREFIX_PATH="$prefix" > "$work/$ex.configure.log" ||
    { cat "$work/$ex.configure.log"; exit 1; }
  cmake --build "$work/$ex" -j2 > "$work/$ex.build.log" || { cat "$work/$ex.build.log"; exit 1; }
done

hprt="$prefix/bin/hprt"
"$work/consumer/hprt_consumer" "" random 20000 2> /dev/null && {
  echo "test_examples: the consumer accepted an empty mesh path" >&2; exit 1; } || true
"$work/consumer/hprt_consumer" | tee "$work/consumer.out"
grep -q "wrong on 0 rays: pass" "$work/consumer.out"

"$hprt" generate bumpy --tris 20000 -o "$work/bumpy.ply"
"$work/consumer/hprt_consumer" "$work/bumpy.ply" diffuse 20000 > /dev/null

expect() {  # expect EXIT_CODE COMMAND...: runs it, prints its output, checks its exit code
  local want=$1 rc=0
  shift
  "$@" || rc=$?
  [[ $rc == "$want" ]] || { echo "test_examples: exit $rc (expected $want): $*" >&2; exit 1; }
}
bvh_plugin="plugin:$work/plugin_bvh/libhprt_plugin_bvh.so"
expect 0 "$hprt" validate rays "$work/bumpy.ply" --kind random -n 20000 --backend "$bvh_plugin"
expect 0 "$hprt" validate rays "$work/bumpy.ply" --kind edge-probe -n 5000 \
  --backend "$bvh_plugin:layout=bvh4,builder=binned" --reference bvh
expect 2 "$hprt" validate rays "$work/bumpy.ply" --kind random -n 10 --backend "$bvh_plugin:leaf_size=0"
expect 0 "$hprt" validate rays "$work/bumpy.ply" --kind random -n 3000 \
  --backend "plugin:$work/plugin_bruteforce_c/libhprt_bruteforce.so"
expect 0 "$hprt" validate rays "$work/bumpy.ply" --kind shadow -n 3000 --occluded \
  --backend "plugin:$work/plugin_bruteforce_c/libhprt_bruteforce.so"
expect 1 "$hprt" validate rays "$work/bumpy.ply" --kind random -n 3000 \
  --backend "plugin:$work/plugin_bruteforce_c/libhprt_bruteforce_broken.so" --mismatches "$work/m.rays"
expect 0 "$hprt" bench trace "$work/bumpy.ply" --quick --no-suite --backend "$bvh_plugin"
# The Python module from the prefix, when the build made it (HPRT_BUILD_PYTHON).
pydir="$prefix/lib/python3/dist-packages"
if compgen -G "$pydir/hprt*.so" > /dev/null; then
  PYTHONPATH="$pydir" /usr/bin/python3 -c "
import hprt
s = hprt.RaycastingScene()
s.add_triangles('$work/bumpy.ply')
rays = hprt.RaycastingScene.create_rays_pinhole(60, [0, 0, 0], [0, 0, 4], [0, 1, 0], 64, 48)
r = hprt.validate_rays(s, rays)
assert r['backend_wrong'] == 0, r['summary']
print('test_examples: installed Python module:', hprt.__version__, int((s.cast_rays(rays)['t_hit'] < 1e30).sum()), 'hits')
"
fi
echo "test_examples: all examples built and ran against $prefix"
