"""The hprt Python module: Open3D's RaycastingScene API over hprt, numpy in
and out, arrays read in place, every bad input a Python exception with the
CLI's one-line message (never a crash)."""
import math
import os

import numpy as np
import pytest

import hprt

SOURCE = os.environ.get("HPRT_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))


def grid(n=8):
    """An n x n grid of quads in the plane z = 0 over [-1, 1]^2."""
    xs = np.linspace(-1.0, 1.0, n + 1, dtype=np.float32)
    xv, yv = np.meshgrid(xs, xs)
    vertices = np.stack([xv.ravel(), yv.ravel(), np.zeros(xv.size, np.float32)], axis=1)
    tris = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            tris += [[a, a + 1, a + n + 2], [a, a + n + 2, a + n + 1]]
    return np.ascontiguousarray(vertices), np.array(tris, dtype=np.uint32)


def down(x, y, z=2.0):
    return [x, y, z, 0.0, 0.0, -1.0]


@pytest.mark.parametrize("backend", ["bvh", "embree"])
def test_cast_rays_shapes_dtypes_and_answers(backend):
    scene = hprt.RaycastingScene(backend=backend)
    v, t = grid()
    assert scene.add_triangles(v, t) == 0
    rays = np.array([[down(0.1, 0.2), down(3.0, 0.0)], [down(-0.5, 0.5), down(0.9, -0.9)]],
                    dtype=np.float32)
    ans = scene.cast_rays(rays)
    assert set(ans) == {"t_hit", "geometry_ids", "primitive_ids", "primitive_uvs",
                        "primitive_normals"}
    assert ans["t_hit"].shape == (2, 2) and ans["t_hit"].dtype == np.float32
    assert ans["geometry_ids"].dtype == np.uint32 and ans["primitive_ids"].dtype == np.uint32
    assert ans["primitive_uvs"].shape == (2, 2, 2)
    assert ans["primitive_normals"].shape == (2, 2, 3)
    np.testing.assert_allclose(ans["t_hit"][0, 0], 2.0)
    assert math.isinf(ans["t_hit"][0, 1])
    assert ans["geometry_ids"][0, 1] == hprt.RaycastingScene.INVALID_ID
    assert ans["primitive_ids"][0, 1] == hprt.INVALID_ID
    assert ans["primitive_ids"][0, 0] < len(t)
    np.testing.assert_allclose(np.abs(ans["primitive_normals"][0, 0]), [0, 0, 1])
    np.testing.assert_array_equal(ans["primitive_normals"][0, 1], [0, 0, 0])
    occ = scene.test_occlusions(rays)
    assert occ.dtype == np.bool_ and occ.tolist() == [[True, False], [True, True]]
    assert scene.test_occlusions(rays, tnear=0.0, tfar=1.5).tolist() == [[False, False]] * 2
    info = scene.info()
    assert info["triangles"] == len(t) and info["geometries"] == 1
    assert info["backend"].startswith(backend)


def test_any_array_like_and_dtype():
    v, t = grid(4)
    scene = hprt.RaycastingScene(nthreads=2)
    scene.add_triangles(v.astype(np.float64).tolist(), t.astype(np.int64))
    rays64 = np.array([down(0.25, 0.25)], dtype=np.float64)
    a = scene.cast_rays(rays64)
    b = scene.cast_rays([down(0.25, 0.25)], nthreads=1)
    assert a["t_hit"].tolist() == b["t_hit"].tolist() == [2.0]
    one = scene.cast_rays(np.array(down(0.25, 0.25), np.float32))  # a single ray: shape ()
    assert one["t_hit"].shape == () and one["primitive_uvs"].shape == (2,)
    empty = scene.cast_rays(np.zeros((0, 6), np.float32))
    assert empty["t_hit"].shape == (0,)


def test_nan_rays_miss_and_empty_scene():
    scene = hprt.RaycastingScene()
    v, t = grid(2)
    scene.add_triangles(v, t)
    rays = np.array([[math.nan, 0, 2, 0, 0, -1], [0, 0, 2, 0, 0, 0], [0, 0, 2, math.inf, 0, -1]],
                    np.float32)
    assert np.isinf(scene.cast_rays(rays)["t_hit"]).all()
    assert not scene.test_occlusions(rays).any()
    empty = hprt.RaycastingScene()
    assert np.isinf(empty.cast_rays([down(0, 0)])["t_hit"]).all()
    empty.add_triangles(np.zeros((0, 3), np.float32), np.zeros((0, 3), np.int32))
    assert np.isinf(empty.cast_rays([down(0, 0)])["t_hit"]).all()
    assert empty.info()["triangles"] == 0


def test_arrays_are_copied_and_update_triangles():
    v, t = grid(8)
    rays = np.array([down(0.3, -0.2), down(5.3, -0.2)], np.float32)
    for update in ["auto", "refit", "rebuild", "adaptive"]:
        scene = hprt.RaycastingScene(update=update)
        # The scene copies its arrays, as Open3D's does: one buffer reused
        # for two geometries gives two geometries.
        buf = v.copy()
        gid = scene.add_triangles(buf, t)
        buf[:, 0] += 5.0
        assert scene.add_triangles(buf, t) == gid + 1
        ans = scene.cast_rays(rays)
        assert ans["t_hit"].tolist() == [2.0, 2.0] and ans["geometry_ids"].tolist() == [0, 1]
        moved = v.copy()
        moved[:, 2] = -1.0
        scene.update_triangles(gid, moved)
        assert scene.cast_rays(rays)["t_hit"].tolist() == [3.0, 2.0]
        # Changing the array afterwards changes nothing until update_triangles.
        moved[:, 2] = 0.5
        assert scene.cast_rays(rays)["t_hit"].tolist() == [3.0, 2.0]
        scene.update_triangles(gid, moved)
        assert scene.cast_rays(rays)["t_hit"][0] == pytest.approx(1.5)


def test_normals_follow_moved_and_added_triangles():
    # cast_rays' normals come from the backend's trace and follow moved
    # triangles; the per-triangle normals the scene keeps for
    # compute_closest_points are remade after update_triangles and
    # add_triangles, and info() reports their memory.
    v, t = grid(8)
    scene = hprt.RaycastingScene()
    gid = scene.add_triangles(v, t)
    assert scene.info()["normals_bytes"] == 0
    rays = np.array([down(0.3, -0.2)], np.float32)
    np.testing.assert_allclose(np.abs(scene.cast_rays(rays)["primitive_normals"][0]), [0, 0, 1],
                               atol=1e-6)
    assert scene.info()["normals_bytes"] == 0  # cast_rays keeps none of its own
    tilted = v.copy()
    tilted[:, 2] = 0.5 * v[:, 0]  # the plane z = x / 2
    scene.update_triangles(gid, tilted)
    ans = scene.cast_rays(rays)
    assert ans["t_hit"][0] == pytest.approx(1.85)
    n = ans["primitive_normals"][0] * np.sign(ans["primitive_normals"][0][2])
    np.testing.assert_allclose(n, np.array([-0.5, 0.0, 1.0]) / math.sqrt(1.25), atol=1e-6)
    cv, ct = cube()
    cid = scene.add_triangles(cv, ct)
    c = scene.compute_closest_points(cv[ct[0]].mean(axis=0, keepdims=True))
    assert c["geometry_ids"][0] == cid
    np.testing.assert_allclose(c["primitive_normals"],
                               expected_normals([(tilted, t), (cv, ct)], c["geometry_ids"],
                                                c["primitive_ids"]), atol=1e-6)
    assert scene.info()["normals_bytes"] == 12 * (len(t) + len(ct))


def test_queries_from_several_threads_at_once():
    # The GIL is released during queries: threads that query a scene nobody
    # has queried yet (backend and normals made by whichever comes first)
    # all get the answers of a scene queried from one thread.
    import threading
    v, t = grid(32)
    rng = np.random.default_rng(3)
    org = np.hstack([rng.uniform(-1.2, 1.2, (5000, 2)), np.full((5000, 1), 2.0)])
    rays = np.hstack([org, rng.normal(size=(5000, 3)) * [0.3, 0.3, 0.0] + [0, 0, -1]])
    reference = hprt.RaycastingScene()
    reference.add_triangles(v, t)
    expected = reference.cast_rays(rays)
    scene = hprt.RaycastingScene()
    scene.add_triangles(v, t)
    answers = [None] * 4
    workers = [threading.Thread(target=lambda i=i: answers.__setitem__(i, scene.cast_rays(rays)))
               for i in range(len(answers))]
    for w in workers:
        w.start()
    for w in workers:
        w.join()
    for ans in answers:
        for key in expected:
            np.testing.assert_array_equal(ans[key], expected[key])


def test_result_arrays_reused_after_free_are_fully_rewritten():
    # Result arrays of 2 MiB or more come from memory kept for reuse (one
    # for the process) once they are freed: a result still held is never written by a
    # later call, one freed is rewritten in full (stale hits from the last
    # call would show here as hits of rays that miss), and a result outlives
    # its scene.
    v, t = grid(16)
    n = 600_000
    rng = np.random.default_rng(5)
    hits = np.hstack([rng.uniform(-0.9, 0.9, (n, 2)), np.full((n, 1), 2.0),
                      np.tile([0.0, 0.0, -1.0], (n, 1))]).astype(np.float32)
    misses = hits.copy()
    misses[:, 0] += 5.0
    scene = hprt.RaycastingScene()
    scene.add_triangles(v, t)
    kept = scene.cast_rays(hits)
    expected = {k: a.copy() for k, a in kept.items()}
    assert np.all(kept["t_hit"] == 2.0)
    for _ in range(2):
        ans = scene.cast_rays(misses)  # the second time in the first's freed memory
        assert np.all(np.isinf(ans["t_hit"]))
        assert np.all(ans["geometry_ids"] == hprt.INVALID_ID)
        assert np.all(ans["primitive_ids"] == hprt.INVALID_ID)
        assert not ans["primitive_uvs"].any() and not ans["primitive_normals"].any()
        for key in kept:
            assert not np.shares_memory(ans[key], kept[key])
            ans[key][...] = 1  # writable
        del ans
        assert scene.info()["result_cache_bytes"] >= 4 * n * (1 + 1 + 1 + 2 + 3)
        # One memory for the process: another scene sees (and reuses) it.
        assert (hprt.RaycastingScene().info()["result_cache_bytes"]
                == scene.info()["result_cache_bytes"])
    assert scene.test_occlusions(misses).sum() == 0 and scene.test_occlusions(hits).all()
    counts = scene.count_intersections(misses)
    assert counts.dtype == np.int32 and not counts.any()
    assert np.all(scene.count_intersections(hits) == 1)
    far = np.tile(np.array([[0.0, 0.0, 7.0]], np.float32), (n, 1))
    assert np.all(scene.compute_distance(far) == 7.0)
    assert not scene.compute_distance(far * 0.0).any()  # on the surface
    del scene
    for key in kept:
        np.testing.assert_array_equal(kept[key], expected[key])


def test_backend_options_and_plugins():
    v, t = grid(4)
    scene = hprt.RaycastingScene(builder="morton", layout="bvh4", leaf_size=2)
    scene.add_triangles(v, t)
    scene.cast_rays([down(0, 0)])
    assert scene.info()["backend"] == "bvh/morton/watertight/bvh4"
    blocks = hprt.RaycastingScene(sah_leaf_block=4, leaf_size=16)
    blocks.add_triangles(v, t)
    assert blocks.cast_rays([down(0.1, 0.1)])["t_hit"][0] == pytest.approx(2.0)
    robust = hprt.RaycastingScene(backend="embree", robust=True, quality="high")
    robust.add_triangles(v, t)
    assert robust.cast_rays([down(0.1, 0.1)])["t_hit"][0] == pytest.approx(2.0)
    good = os.environ.get("HPRT_TEST_PLUGIN_GOOD")
    if good:
        p = hprt.RaycastingScene(backend="plugin:" + good)
        p.add_triangles(v, t)
        assert p.cast_rays([down(0.1, 0.1)])["t_hit"][0] == pytest.approx(2.0)
        assert p.info()["backend"] == "plugin/test"


def test_validate_rays():
    v, t = grid(16)
    scene = hprt.RaycastingScene()
    scene.add_triangles(v, t)
    rays = hprt.RaycastingScene.create_rays_pinhole(60, [0, 0, 0], [0.3, 0.2, 3], [0, 1, 0], 64,
                                                    48)
    r = hprt.validate_rays(scene, rays)
    assert r["rays"] == 64 * 48 and r["backend_wrong"] == 0
    assert r["verdicts"].shape == (48, 64) and r["verdicts"].dtype == np.uint8
    assert "wrong on 0 rays: pass" in r["summary"]
    assert hprt.validate_rays(scene, rays, reference="bvh")["mismatches"] == 0
    lies = os.environ.get("HPRT_TEST_PLUGIN_MALFORMED")
    if lies:
        bad = hprt.RaycastingScene(backend="plugin:" + lies)
        bad.add_triangles(v, t)
        r = hprt.validate_rays(bad, rays)
        assert r["backend_malformed"] > 100 and r["backend_wrong"] >= r["backend_malformed"]
        assert "FAIL" in r["summary"]


def test_create_rays_pinhole_forms_agree():
    rays = hprt.RaycastingScene.create_rays_pinhole(fov_deg=90, center=[0, 0, 0], eye=[0, 0, 5],
                                                    up=[0, 1, 0], width_px=8, height_px=6)
    assert rays.shape == (6, 8, 6) and rays.dtype == np.float32
    np.testing.assert_allclose(rays[..., :3], np.broadcast_to([0, 0, 5], (6, 8, 3)))
    # The centre of the image looks at the centre point.
    mid = (rays[2, 3, 3:] + rays[3, 4, 3:]) / 2
    assert mid[2] < 0 and abs(mid[0]) < 1e-6 and abs(mid[1]) < 1e-6
    f = 0.5 * 8 / math.tan(math.radians(45))
    k = [[f, 0, 4], [0, f, 3], [0, 0, 1]]
    ext = np.eye(4)
    # Open3D's look-at: rows right = up x forward, up, forward (-z here).
    ext[:3, :3] = [[-1, 0, 0], [0, 1, 0], [0, 0, -1]]
    ext[:3, 3] = [0, 0, 5]
    rays2 = hprt.RaycastingScene.create_rays_pinhole(k, ext, 8, 6)
    np.testing.assert_allclose(rays2[..., :3], rays[..., :3], atol=1e-6)
    np.testing.assert_allclose(rays2[..., 3:], rays[..., 3:], atol=1e-5)
    with pytest.raises(hprt.Error, match="fov_deg"):
        hprt.RaycastingScene.create_rays_pinhole(0, [0, 0, 0], [0, 0, 1], [0, 1, 0], 4, 4)


def test_files_render_and_load_mesh(tmp_path):
    obj = tmp_path / "tri.obj"
    obj.write_text("v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n")
    vertices, triangles = hprt.load_mesh(str(obj))
    assert vertices.shape == (3, 3) and vertices.dtype == np.float32
    assert triangles.tolist() == [[0, 1, 2]] and triangles.dtype == np.uint32
    scene = hprt.RaycastingScene()
    assert scene.add_triangles(obj) == 0  # a path (str or PathLike)
    assert scene.cast_rays([down(0, 0)])["t_hit"][0] == pytest.approx(2.0)
    img = hprt.render(str(obj), 32, 24, backend="embree")
    assert img.shape == (24, 32, 3) and img.dtype == np.float32
    same = hprt.render(str(obj), 32, 24)
    assert np.abs(img - same).max() < 0.05
    scene_json = os.path.join(SOURCE, "data", "scenes", "single_13mm.json")
    if os.path.exists(scene_json):
        assert hprt.render(scene_json, 40)[..., 0].shape == (30, 40)


def test_bad_input_raises_with_the_cli_message(tmp_path):
    scene = hprt.RaycastingScene()
    v, t = grid(2)
    with pytest.raises(ValueError, match="vertex_positions"):
        scene.add_triangles(v[:, :2], t)
    with pytest.raises(ValueError, match="triangle_indices"):
        scene.add_triangles(v, t[:, :2])
    with pytest.raises(ValueError, match="out of range"):
        scene.add_triangles(v, t + 100)
    with pytest.raises(ValueError, match="out of range"):
        scene.add_triangles(v, -t.astype(np.int64) - 1)
    with pytest.raises(TypeError):
        scene.add_triangles(v, t.astype(np.float32))
    with pytest.raises(TypeError):
        scene.add_triangles(np.array([["a", "b", "c"]]), t)
    with pytest.raises(TypeError):
        scene.add_triangles(42)
    with pytest.raises(ValueError, match="rays"):
        scene.cast_rays(np.zeros((3, 5), np.float32))
    with pytest.raises(TypeError):
        scene.cast_rays(np.zeros((3, 6), np.complex64))
    with pytest.raises(FileNotFoundError, match="nothing.obj"):
        scene.add_triangles(str(tmp_path / "nothing.obj"))
    with pytest.raises(FileNotFoundError):
        hprt.load_mesh(str(tmp_path / "nothing.ply"))
    bad = tmp_path / "bad.ply"
    bad.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 999999999999\nend_header\n")
    with pytest.raises(hprt.Error, match="bad.ply"):
        hprt.load_mesh(str(bad))
    with pytest.raises(hprt.Error, match="leaf_size"):
        hprt.RaycastingScene(leaf_size=0)
    with pytest.raises(hprt.Error, match="unknown backend option"):
        hprt.RaycastingScene(colour="red")
    with pytest.raises(hprt.Error, match="unknown backend"):
        hprt.RaycastingScene(backend="optix")
    with pytest.raises(hprt.Error, match="plugin file not found"):
        hprt.RaycastingScene(backend="plugin:/no/such/plugin.so")
    with pytest.raises(hprt.Error, match="nthreads"):
        hprt.RaycastingScene(nthreads=4097)
    with pytest.raises(hprt.Error, match="width_px, height_px: 100000 x 100000 rays"):
        hprt.RaycastingScene.create_rays_pinhole(60, [0, 0, 0], [0, 0, 1], [0, 1, 0],
                                                 100000, 100000)
    with pytest.raises(ValueError, match="render: image size above 65536"):
        hprt.render(os.path.join(SOURCE, "data", "scenes", "single_13mm.json"), 70000, 10)
    for n in (4097, 10**9):  # per call too (a huge task arena crashed oneTBB)
        with pytest.raises(hprt.Error, match=r"nthreads: must be at most 4096"):
            scene.cast_rays(np.zeros((1, 6), np.float32), nthreads=n)
        with pytest.raises(hprt.Error, match="nthreads"):
            scene.compute_distance(np.zeros((1, 3), np.float32), nthreads=n)
    gid = scene.add_triangles(v, t)
    with pytest.raises(hprt.Error, match="geometry_id"):
        scene.update_triangles(gid + 5, v)
    with pytest.raises(hprt.Error, match="vertex_positions"):
        scene.update_triangles(gid, v[:2])
    with pytest.raises(hprt.Error, match="unknown ray kind|reference|unknown backend"):
        hprt.validate_rays(scene, [down(0, 0)], reference="nope")
    assert issubclass(hprt.Error, RuntimeError)


def cube():
    """The closed cube [-1, 1]^3 as 12 triangles (both diagonals' ends shared)."""
    v = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                  [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=np.float32)
    t = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
                  [3, 7, 6], [3, 6, 2], [0, 4, 7], [0, 7, 3], [1, 2, 6], [1, 6, 5]],
                 dtype=np.int64)
    return v, t


def test_count_intersections_counts_every_crossing_once():
    scene = hprt.RaycastingScene()
    scene.add_triangles(*cube())
    rays = np.array([
        [0, 0, 0, 0.3, 0.2, 1],      # from inside: one crossing
        [0, 0, 0, 1, 1, 1],          # exactly through a corner shared by six triangles
        [0, 0, 0, 0.5, 0.5, 1],      # exactly through a face diagonal (shared edge)
        [-5, 0, 0, 1, 0, 0],         # in and out, both through face diagonals
        [-5, 3, 0, 1, 0, 0],         # beside
        [0, 0, 0, float("nan"), 0, 1],  # NaN: no crossing, as in the CLI
    ], dtype=np.float32)
    counts = scene.count_intersections(rays)
    assert counts.dtype == np.int32 and counts.shape == (6,)
    assert counts.tolist() == [1, 1, 1, 2, 0, 0]
    assert scene.count_intersections(rays.reshape(2, 3, 6)).shape == (2, 3)
    # Parity: inside for points of a grid through the cube's centre planes,
    # including points on the diagonals' planes.
    pts = np.array([[x, y, z] for x in (-0.5, 0.0, 0.5) for y in (-0.5, 0.0, 0.5)
                    for z in (-2.0, 0.0, 2.0)], dtype=np.float32)
    dirs = np.tile(np.array([[1.0, 1.0, 0.0]], np.float32), (len(pts), 1))
    parity = scene.count_intersections(np.hstack([pts, dirs])) % 2
    assert parity.tolist() == [int(abs(p[2]) < 1) for p in pts]


def test_list_intersections_keys_dtypes_and_order():
    scene = hprt.RaycastingScene()
    scene.add_triangles(*cube())
    rays = np.array([[-5, 0.1, 0.2, 1, 0, 0], [-5, 3, 0, 1, 0, 0], [0, 0, 0, 0, 0, 2]],
                    dtype=np.float32)
    ans = scene.list_intersections(rays)
    assert set(ans) == {"ray_splits", "ray_ids", "geometry_ids", "primitive_ids",
                        "primitive_uvs", "t_hit"}
    assert ans["ray_splits"].dtype == np.uint32 and ans["ray_splits"].tolist() == [0, 2, 2, 3]
    assert ans["ray_ids"].dtype == np.uint32 and ans["ray_ids"].tolist() == [0, 0, 2]
    assert ans["primitive_uvs"].shape == (3, 2) and ans["primitive_uvs"].dtype == np.float32
    np.testing.assert_allclose(ans["t_hit"], [4.0, 6.0, 0.5])
    assert (ans["geometry_ids"] == 0).all() and (ans["primitive_ids"] < 12).all()
    counts = scene.count_intersections(rays)
    assert np.diff(ans["ray_splits"]).tolist() == counts.tolist()
    empty = scene.list_intersections(np.zeros((0, 6), np.float32))
    assert empty["ray_splits"].tolist() == [0] and empty["t_hit"].shape == (0,)


def test_count_and_list_through_embree_and_bad_input():
    scene = hprt.RaycastingScene(backend="embree")
    scene.add_triangles(*cube())
    rays = np.array([[-5, 0.1, 0.2, 1, 0, 0]], dtype=np.float32)
    assert scene.count_intersections(rays).tolist() == [2]
    assert scene.list_intersections(rays)["ray_splits"].tolist() == [0, 2]
    with pytest.raises(ValueError):
        scene.count_intersections(np.zeros((3, 5), np.float32))
    with pytest.raises(ValueError):
        scene.list_intersections(np.zeros((3, 7), np.float32))


def test_closest_points_keys_dtypes_shapes_and_answers():
    scene = hprt.RaycastingScene()
    scene.add_triangles(*cube())
    pts = np.array([[0.2, 0.1, 0.0], [3.0, 0.0, 0.0], [1.0, 0.5, 0.25], [2.0, 2.0, 2.0]])
    ans = scene.compute_closest_points(pts)  # float64 in: converted once
    assert set(ans) == {"points", "geometry_ids", "primitive_ids", "primitive_uvs",
                        "primitive_normals"}
    assert ans["points"].dtype == np.float32 and ans["points"].shape == (4, 3)
    assert ans["geometry_ids"].dtype == np.uint32 and ans["primitive_ids"].shape == (4,)
    assert ans["primitive_uvs"].shape == (4, 2) and ans["primitive_normals"].shape == (4, 3)
    np.testing.assert_allclose(ans["points"], [[1, 0.1, 0], [1, 0, 0], [1, 0.5, 0.25], [1, 1, 1]],
                               atol=1e-6)
    np.testing.assert_allclose(np.abs(ans["primitive_normals"][:3, 0]), 1.0, atol=1e-6)
    dist = scene.compute_distance(pts)
    assert dist.dtype == np.float32 and dist.shape == (4,)
    np.testing.assert_allclose(dist, [0.8, 2.0, 0.0, math.sqrt(3.0)], rtol=1e-6)
    assert dist[2] == 0.0
    # Leading dimensions are kept; the same answers in another shape.
    grid3 = pts.astype(np.float32).reshape(2, 2, 3)
    assert scene.compute_distance(grid3).shape == (2, 2)
    np.testing.assert_array_equal(scene.compute_distance(grid3).ravel(), dist)
    assert scene.compute_closest_points(grid3)["primitive_uvs"].shape == (2, 2, 2)
    # Embree's rtcPointQuery with the same callback: the same distances.
    emb = hprt.RaycastingScene(backend="embree")
    emb.add_triangles(*cube())
    np.testing.assert_array_equal(emb.compute_distance(pts), dist)


def test_signed_distance_and_occupancy_are_exact():
    scene = hprt.RaycastingScene()
    scene.add_triangles(*cube())
    # Every point of a grid with steps of 1/4: on the cube's faces, edges,
    # corners, its face diagonals' planes, inside and outside.
    g = np.arange(-6, 7, dtype=np.float32) / 4
    pts = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    m = np.abs(pts).max(axis=1)
    occ = scene.compute_occupancy(pts)
    assert occ.dtype == np.float32 and occ.shape == (len(pts),)
    np.testing.assert_array_equal(occ, (m <= 1).astype(np.float32))
    sd = scene.compute_signed_distance(pts, nsamples=3)
    assert sd.dtype == np.float32
    assert (sd[m < 1] < 0).all() and (sd[m == 1] == 0).all() and (sd[m > 1] > 0).all()
    np.testing.assert_allclose(np.abs(sd), scene.compute_distance(pts))
    np.testing.assert_allclose(sd[m < 1], m[m < 1] - 1, atol=1e-6)


def test_point_queries_bad_input_and_edge_cases():
    scene = hprt.RaycastingScene()
    assert scene.compute_distance(np.zeros((2, 3), np.float32)).tolist() == [math.inf] * 2
    scene.add_triangles(*cube())
    empty = scene.compute_closest_points(np.zeros((0, 3), np.float32))
    assert empty["points"].shape == (0, 3)
    nan = scene.compute_closest_points([[float("nan"), 0, 0], [0, 1e30, 0]])
    assert (nan["primitive_ids"] == hprt.INVALID_ID).all()
    assert np.isinf(scene.compute_distance([[float("nan"), 0, 0]])).all()
    assert scene.compute_occupancy([[float("nan"), 0, 0]]).tolist() == [0.0]
    for f in (scene.compute_closest_points, scene.compute_distance,
              scene.compute_signed_distance, scene.compute_occupancy):
        with pytest.raises(ValueError):
            f(np.zeros((4, 2), np.float32))
        with pytest.raises(TypeError):
            f(np.array([["a", "b", "c"]]))
    with pytest.raises(hprt.Error, match="nsamples"):
        scene.compute_occupancy([[0, 0, 0]], nsamples=2)
    with pytest.raises(hprt.Error, match="nsamples"):
        scene.compute_signed_distance([[0, 0, 0]], nsamples=0)
    mt = hprt.RaycastingScene(isect="mt")
    mt.add_triangles(*cube())
    with pytest.raises(hprt.Error, match="watertight"):
        mt.compute_occupancy([[0, 0, 0]])


def expected_normals(geoms, gids, pids):
    """Unit (b - a) x (c - a) of each named triangle, numpy in double."""
    out = np.zeros((len(pids), 3))
    for k, (g, p) in enumerate(zip(gids, pids)):
        if p == hprt.RaycastingScene.INVALID_ID:
            continue
        v, t = geoms[g]
        a, b, c = (v[i].astype(np.float64) for i in t[p])
        n = np.cross(b - a, c - a)
        out[k] = n / np.linalg.norm(n)
    return out


def test_normals_of_many_hits_and_closest_points_over_two_geometries():
    # Enough queries that the normals' prefetching pipeline runs in full,
    # over two meshes (ids, hits and misses interleaved).
    scene = hprt.RaycastingScene()
    geoms = [grid(16), cube()]
    for v, t in geoms:
        scene.add_triangles(v, t)
    rng = np.random.default_rng(7)
    n = 20_000
    org = rng.uniform(-2.0, 2.0, (n, 3)).astype(np.float32)
    dirs = rng.normal(size=(n, 3)).astype(np.float32)
    ans = scene.cast_rays(np.hstack([org, dirs]))
    gids, pids = ans["geometry_ids"], ans["primitive_ids"]
    assert (pids != hprt.RaycastingScene.INVALID_ID).sum() > n // 4
    assert set(gids[pids != hprt.RaycastingScene.INVALID_ID].tolist()) == {0, 1}
    np.testing.assert_allclose(ans["primitive_normals"], expected_normals(geoms, gids, pids),
                               atol=1e-6)
    c = scene.compute_closest_points(org)
    np.testing.assert_allclose(c["primitive_normals"],
                               expected_normals(geoms, c["geometry_ids"], c["primitive_ids"]),
                               atol=1e-6)


@pytest.mark.parametrize("moved", [False, True])
def test_cast_rays_normals_are_the_same_bits_on_every_backend(moved):
    # The bvh backend computes a hit's normal from the vertices its test read
    # (or, with the mt test, copies it from a table); Embree's scene computes
    # it from the mesh after the trace: the same bits for the same triangle,
    # for every layout, after a refit too. Coherent rays make packets,
    # random ones single rays.
    geoms = [grid(16), cube()]
    rng = np.random.default_rng(11)
    n = 8000
    org = rng.uniform(-2.0, 2.0, (n, 3)).astype(np.float32)
    dirs = rng.normal(size=(n, 3)).astype(np.float32)
    random_rays = np.hstack([org, dirs])
    camera = hprt.RaycastingScene.create_rays_pinhole(60.0, [0, 0, 0], [0.3, 0.4, 3.0], [0, 1, 0],
                                                      64, 48).reshape(-1, 6)
    rays = np.vstack([random_rays, camera])
    answers = {}
    for name, opts in [("bvh", {}), ("bvh", {"isect": "mt"}), ("bvh", {"layout": "bvh2"}),
                       ("bvh", {"layout": "bvh4"}), ("embree", {})]:
        scene = hprt.RaycastingScene(backend=name, **opts)
        ids = [scene.add_triangles(v, t) for v, t in geoms]
        scene.cast_rays(rays[:1])
        if moved:
            v, t = geoms[0]
            bent = v.copy()
            bent[:, 2] = 0.25 * v[:, 0] * v[:, 1]
            scene.update_triangles(ids[0], bent)
        answers[(name, tuple(opts.items()))] = scene.cast_rays(rays)
    geoms_now = geoms
    if moved:
        v, t = geoms[0]
        bent = v.copy()
        bent[:, 2] = 0.25 * v[:, 0] * v[:, 1]
        geoms_now = [(bent, t), geoms[1]]
    first = answers[("bvh", ())]
    hit = first["primitive_ids"] != hprt.RaycastingScene.INVALID_ID
    assert hit.sum() > n // 4
    np.testing.assert_allclose(first["primitive_normals"],
                               expected_normals(geoms_now, first["geometry_ids"],
                                                first["primitive_ids"]), atol=1e-6)
    assert (first["primitive_normals"][~hit] == 0).all()
    for key, ans in answers.items():
        same = (ans["primitive_ids"] == first["primitive_ids"]) & \
               (ans["geometry_ids"] == first["geometry_ids"])
        assert same.mean() > 0.99, key
        np.testing.assert_array_equal(ans["primitive_normals"][same],
                                      first["primitive_normals"][same], err_msg=str(key))


def test_open3d_conventions_paths_and_render_options(tmp_path):
    import pathlib
    v, t = grid(4)
    # nthreads <= 0 means every hardware thread, as in Open3D.
    scene = hprt.RaycastingScene(nthreads=-1)
    scene.add_triangles(v, t)
    assert scene.info()["backend"].startswith("bvh/")  # named before the first query too
    assert scene.cast_rays([down(0.1, 0.1)], nthreads=-3)["t_hit"][0] == pytest.approx(2.0)
    obj = tmp_path / "tri.obj"
    obj.write_text("v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n")
    for path in (obj, str(obj), os.fsencode(str(obj))):  # PathLike, str, bytes everywhere
        assert hprt.load_mesh(path)[1].tolist() == [[0, 1, 2]]
        assert hprt.RaycastingScene().add_triangles(path) == 0
        assert hprt.render(path, 8, 6).shape == (6, 8, 3)
    with pytest.raises(TypeError, match="load_mesh: expected a path"):
        hprt.load_mesh(42)
    # Backend options of render (Python objects read before the GIL is released).
    img = hprt.render(obj, 16, 12, builder="morton", robust=True)
    assert img.shape == (12, 16, 3)
    with pytest.raises(hprt.Error, match="leaf_size"):
        hprt.render(obj, 8, 6, leaf_size=-3)
    with pytest.raises(hprt.Error, match="unknown backend option"):
        hprt.render(pathlib.Path(obj), 8, 6, frobnicate=1)


def test_occlusion_interval_and_index_messages():
    v, t = grid(2)
    scene = hprt.RaycastingScene()
    scene.add_triangles(v, t)
    r = [down(0.1, 0.1)]
    assert scene.test_occlusions(r, tnear=0.0, tfar=2.0).tolist() == [True]
    for tnear, tfar in ((-0.5, 3.0), (2.0, 1.0), (float("nan"), 1.0)):
        with pytest.raises(ValueError, match="tnear, tfar: need 0 <= tnear <= tfar"):
            scene.test_occlusions(r, tnear=tnear, tfar=tfar)
    with pytest.raises(ValueError, match="index 9223372036854775813 out of range"):
        scene.add_triangles(v, np.array([[0, 1, 2**63 + 5]], np.uint64))
    with pytest.raises(ValueError, match=r"vertex_positions: expected shape \(N, 3\)"):
        scene.add_triangles(np.zeros((2, 4, 3), np.float32), t)


def test_conversion_out_of_memory_is_a_memory_error():
    # A float64 array whose float32 copy cannot be made: numpy's MemoryError,
    # not a crash (in a child process, whose address space is capped).
    import subprocess
    import sys
    code = (
        "import resource, numpy as np, hprt\n"
        "s = hprt.RaycastingScene()\n"
        "s.add_triangles(np.float32([[0,0,0],[1,0,0],[0,1,0]]), np.uint32([[0,1,2]]))\n"
        "s.cast_rays(np.float32([[0.2,0.2,-1,0,0,1]]))\n"
        "soft, hard = resource.getrlimit(resource.RLIMIT_AS)\n"
        "used = int(open('/proc/self/statm').read().split()[0]) * resource.getpagesize()\n"
        "resource.setrlimit(resource.RLIMIT_AS, (used + (512 << 20), hard))\n"
        "rays = np.broadcast_to(np.float64([0.2,0.2,-1,0,0,1]), (200_000_000, 6))\n"
        "for f in (s.cast_rays, s.test_occlusions, s.count_intersections, s.list_intersections):\n"
        "    try:\n"
        "        f(rays)\n"
        "    except MemoryError:\n"
        "        continue\n"
        "    raise SystemExit('no MemoryError from ' + f.__name__)\n"
        "print('ok')\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       env=os.environ, timeout=120)
    assert r.returncode == 0 and r.stdout.strip() == "ok", r.stderr


def test_moving_triangles_while_other_threads_query():
    # add_triangles and update_triangles wait for the queries under way (the
    # closest-point query reads the normals a change remakes).
    import threading
    v, t = grid(24)
    scene = hprt.RaycastingScene()
    gid = scene.add_triangles(v, t)
    points = np.random.default_rng(0).uniform(-1, 2, (4000, 3)).astype(np.float32)
    rays = np.array([down(0.3, -0.2)] * 100, np.float32)
    stop = threading.Event()
    errors = []

    def reader(query):
        try:
            while not stop.is_set():
                query()
        except Exception as e:  # noqa: BLE001 - reported below
            errors.append(e)

    workers = [threading.Thread(target=reader, args=(q,)) for q in
               (lambda: scene.compute_closest_points(points), lambda: scene.cast_rays(rays))]
    for w in workers:
        w.start()
    try:
        for k in range(200):
            scene.update_triangles(gid, v + np.float32([0, 0, 0.01 * (k % 7)]))
            if k % 50 == 0:
                scene.add_triangles(v + np.float32([3, 0, 0]), t)
    finally:
        stop.set()
        for w in workers:
            w.join()
    assert not errors
    scene.update_triangles(gid, v)
    assert scene.cast_rays(rays[:1])["t_hit"][0] == pytest.approx(2.0)


def test_plugins_that_keep_arrays_or_answer_nothing():
    v, t = grid(4)
    keep = os.environ.get("HPRT_TEST_PLUGIN_KEEP")
    if keep:
        # A plugin whose update() keeps the build's vertex pointers reads the
        # frame hprt wrote into those same arrays (plugin.h, Memory), even
        # after the caller dropped every array it passed.
        import gc
        scene = hprt.RaycastingScene(backend="plugin:" + keep)
        added, moved = v.copy(), v.copy()
        gid = scene.add_triangles(added, t)
        assert scene.cast_rays([down(0.1, 0.1)])["t_hit"][0] == pytest.approx(2.0)
        moved[:, 2] = -1.0
        scene.update_triangles(gid, moved)
        del added, moved
        gc.collect()
        assert scene.cast_rays([down(0.1, 0.1)])["t_hit"][0] == pytest.approx(3.0)
    silent = os.environ.get("HPRT_TEST_PLUGIN_SILENT")
    if silent:
        # A plugin that writes no answer: every one malformed, warned about,
        # t_hit NaN and occlusion answers a bool array of 0 and 1.
        scene = hprt.RaycastingScene(backend="plugin:" + silent)
        scene.add_triangles(v, t)
        assert scene.info()["backend"] == "plugin/si\\nlent\\x1b[0m"  # control characters escaped
        rays = np.array([down(0.1, 0.1)] * 5, np.float32)
        with pytest.warns(RuntimeWarning, match="gave 5 malformed answers"):
            ans = scene.cast_rays(rays)
        assert np.isnan(ans["t_hit"]).all()
        assert (ans["geometry_ids"] == hprt.INVALID_ID).all()
        with pytest.warns(RuntimeWarning, match="gave 5 malformed answers"):
            occ = scene.test_occlusions(rays)
        assert occ.dtype == np.bool_ and occ.view(np.uint8).tolist() == [1] * 5
        assert scene.info()["malformed_answers"] == 10


def test_malformed_warning_counts_only_the_call():
    import warnings
    lies = os.environ.get("HPRT_TEST_PLUGIN_MALFORMED")
    if not lies:
        pytest.skip("HPRT_TEST_PLUGIN_MALFORMED not set")
    v, t = grid(4)
    scene = hprt.RaycastingScene(backend="plugin:" + lies)
    scene.add_triangles(v, t)
    hits = np.array([down(0.1 * k - 0.5, 0.2) for k in range(12)], np.float32)
    with pytest.warns(RuntimeWarning, match="malformed answers"):
        scene.cast_rays(hits)
    before = scene.info()["malformed_answers"]
    assert before > 0
    scene.add_triangles(v + np.float32([10, 0, 0]), t)  # rebuilt at the next query
    assert scene.info()["malformed_answers"] == before
    misses = np.array([down(50.0, 50.0)] * 4, np.float32)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no warning: this call's answers are all well formed
        assert np.isinf(scene.cast_rays(misses)["t_hit"]).all()


def test_argument_type_errors_are_one_line():
    # pybind11's own message spans lines and prints the arrays; hprt's names
    # the call and the argument types on one line.
    scene = hprt.RaycastingScene()
    v, t = grid(2)
    scene.add_triangles(v, t)
    rays = np.zeros((1000, 6), np.float32)
    calls = [lambda: scene.cast_rays(rays, nthreads=None),
             lambda: scene.test_occlusions(rays, tnear="a"),
             lambda: scene.update_triangles(-1, v),
             lambda: hprt.RaycastingScene.create_rays_pinhole(60, [0, 0, 0], [0, 0, 1],
                                                              [0, 1, 0], 4.0, 4),
             lambda: hprt.validate_rays(None, rays),
             lambda: hprt.RaycastingScene(nthreads="x"),
             lambda: hprt.load_mesh(),
             lambda: scene.compute_distance(rays[:, :3], nthreads=1.5)]
    for call in calls:
        with pytest.raises(TypeError) as e:
            call()
        assert "\n" not in str(e.value) and "no signature takes (" in str(e.value), str(e.value)
    assert "cast_rays(): no signature takes (ndarray, nthreads=NoneType)" in str(
        pytest.raises(TypeError, calls[0]).value)
    # Conversions the signatures allow still work (an int for a float).
    assert scene.test_occlusions(rays[:1], tnear=0, tfar=2).shape == (1,)
    assert hprt.RaycastingScene.create_rays_pinhole(60, [0, 0, 0], [0, 0, 1], [0, 1, 0], 4,
                                                    4).shape == (4, 4, 6)
