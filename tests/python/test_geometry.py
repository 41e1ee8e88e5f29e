# Shapes, exact point queries, shape pairs and distance fields from Python: arrays in and out,
# every error a Python exception, the numbers the C++ tool prints to the last bit, Jacobians
# against central differences.
import csv
import io
import subprocess

import numpy as np
import pytest

import pushgraph as pg
from conftest import TOOL

RING = np.array([[0, 0], [0.1, 0], [0.1, 0.06], [0.06, 0.06], [0.06, 0.03], [0.04, 0.03], [0.04, 0.06], [0, 0.06]])
HOLE = np.array([[0.07, 0.01], [0.09, 0.01], [0.09, 0.02], [0.07, 0.02]])


def random_points(n, seed=1, box=0.12):
    return np.random.default_rng(seed).uniform(-box, box, (n, 2))


def test_shapes_from_arrays_and_back():
    s = pg.Shape.from_arrays(RING, [HOLE])
    assert s.num_vertices == 12
    assert s.area == pytest.approx(0.1 * 0.06 - 0.02 * 0.03 - 0.02 * 0.01, rel=1e-12)
    assert not s.is_convex
    np.testing.assert_array_equal(s.bounds, [[0, 0], [0.1, 0.06]])
    again = pg.Shape.from_polygons(s.polygons()["polygons"])
    assert again.area == s.area
    # Clockwise input is normalized; a dict and a bare outline are the same polygon.
    assert pg.Shape.from_polygons([RING[::-1]]).area == pg.Shape.from_polygons([{"outer": RING}]).area
    assert pg.Shape.from_json(s.to_json()).area == s.area
    assert pg.Shape.disk(0.005).radius == 0.005
    assert pg.Shape.box(0.09, 0.09).area == pytest.approx(0.0081)
    assert pg.Shape.regular_polygon(6, 0.05).num_vertices == 6
    moved = s.transformed((1.0, 2.0, 0.0), scale=0.5)
    np.testing.assert_allclose(moved.bounds, [[1.0, 2.0], [1.05, 2.03]])


def test_bad_shapes_name_what_and_where():
    bowtie = np.array([[0, 0], [1, 1], [1, 0], [0, 1]], dtype=float)
    with pytest.raises(pg.GeometryError, match="polygon 0, outer boundary, vertex 0: ring is not simple"):
        pg.Shape.from_arrays(bowtie)
    with pytest.raises(ValueError, match=r"outer\[2, 0\] is nan: every entry must be finite"):
        pg.Shape.from_arrays([[0, 0], [1, 0], [np.nan, 1]])
    # A bool inside a list or tuple is no number, as a bool array is not (NumPy read it as 1).
    with pytest.raises(TypeError, match="points: expected real numbers, got a bool"):
        pg.Shape.box(0.1, 0.06).signed_distance([[True, 0.0]])
    with pytest.raises(TypeError, match="got a bool"):
        pg.Shape.box(0.1, 0.06).transformed((True, 0, 0))
    with pytest.raises(TypeError, match="got a bool"):
        pg.Shape.box(0.1, 0.06).signed_distance([[np.True_, 0.0]])
    # A list holding itself is NumPy's error, not a crash (the bool scan recursed without end).
    loop = []
    loop.append(loop)
    with pytest.raises((ValueError, TypeError)):
        pg.Shape.box(0.1, 0.06).signed_distance(loop)
    with pytest.raises(ValueError, match=r"shape \(N, 2\), got \(3, 3\)"):
        pg.Shape.from_arrays(np.zeros((3, 3)))
    with pytest.raises(ValueError, match="unknown key 'hole'"):
        pg.Shape.from_polygons([{"outer": RING, "hole": [HOLE]}])
    with pytest.raises(pg.GeometryError, match="no_such_file.json: cannot open file"):
        pg.Shape.load_json("/nonexistent/no_such_file.json")
    assert issubclass(pg.GeometryError, ValueError) and issubclass(pg.IoError, OSError)


def test_query_arrays_shapes_dtypes_and_bad_arrays(notched_block):
    pts = random_points(50)
    q = notched_block.query(pts)
    assert q["signed_distance"].shape == (50,) and q["signed_distance"].dtype == np.float64
    assert q["closest_point"].shape == (50, 2) and q["normal"].shape == (50, 2)
    assert q["containment"].dtype == np.int8 and set(np.unique(q["containment"])) <= {pg.OUTSIDE, pg.ON_BOUNDARY, pg.INSIDE}
    assert np.all((q["containment"] == pg.INSIDE) == (q["signed_distance"] < 0))
    assert q["feature_kind"].dtype == np.int8 and q["feature_index"].dtype == np.int32
    # Any dtype and layout of numbers: ints, float32, a strided view, a single point, lists.
    np.testing.assert_array_equal(notched_block.signed_distance(pts[::2]), q["signed_distance"][::2])
    f32 = pts.astype(np.float32)
    np.testing.assert_array_equal(notched_block.signed_distance(f32), notched_block.signed_distance(f32.astype(np.float64)))
    assert notched_block.signed_distance([0.0, 0.0]).shape == (1,)
    assert notched_block.signed_distance(np.zeros((0, 2))).shape == (0,)
    assert notched_block.signed_distance(np.array([[1, 2]], dtype=np.int64))[0] > 0
    with pytest.raises(ValueError, match=r"points\[3, 1\] is inf"):
        bad = pts.copy()
        bad[3, 1] = np.inf
        notched_block.signed_distance(bad)
    with pytest.raises(ValueError, match=r"expected an array of shape \(N, 2\)"):
        notched_block.signed_distance(np.zeros((4, 3)))
    # A pose is one pose whatever is wrong with it (a pose of two numbers was told to be an (N, 3) array).
    with pytest.raises(ValueError, match=r"pose: expected one pose \(x, y, theta\), got \(2,\)"):
        notched_block.query(pts, pose=(0.01, 0.0))
    with pytest.raises(ValueError, match=r"pose: expected one pose \(x, y, theta\), got 2 poses"):
        notched_block.query(pts, pose=np.zeros((2, 3)))
    for bad in ([["a", "b"]], [[1j, 0.0]], [[True, False]], np.array([[None, 1.0]], dtype=object)):
        with pytest.raises(TypeError, match="points: expected"):
            notched_block.signed_distance(bad)
    with pytest.raises(ValueError, match="need a pose"):
        notched_block.query(pts, jacobians=True)


def test_queries_equal_the_command_line_tool_to_the_last_bit(notched_block, tmp_path):
    pts = random_points(200, seed=7)
    pts[:5] = notched_block.polygons()["polygons"][0]["outer"][:5]  # exactly on vertices
    csv_path = tmp_path / "points.csv"
    with open(csv_path, "w") as f:
        f.write("x,y\n")
        for x, y in pts:
            f.write("%r,%r\n" % (float(x), float(y)))
    shape_path = tmp_path / "shape.json"
    notched_block.save_json(str(shape_path))
    out = subprocess.run([TOOL, "distance", str(shape_path), str(csv_path)], check=True, capture_output=True, text=True).stdout
    rows = list(csv.DictReader(io.StringIO(out)))
    assert len(rows) == len(pts)
    q = notched_block.query(pts)
    for i, row in enumerate(rows):
        assert float(row["signed_distance"]) == q["signed_distance"][i]
        assert float(row["closest_x"]) == q["closest_point"][i, 0] and float(row["closest_y"]) == q["closest_point"][i, 1]
        assert float(row["normal_x"]) == q["normal"][i, 0] and float(row["normal_y"]) == q["normal"][i, 1]


def numeric_jacobian(f, x, h=1e-7):
    x = np.asarray(x, dtype=float)
    cols = []
    for k in range(x.size):
        e = np.zeros_like(x)
        e[k] = h
        cols.append((f(x + e) - f(x - e)) / (2 * h))
    return np.stack(cols, axis=-1)


def test_point_query_jacobians_against_central_differences(notched_block):
    rng = np.random.default_rng(3)
    pose = np.array([0.01, -0.02, 0.4])
    pts = rng.uniform(-0.1, 0.1, (40, 2))
    q = notched_block.query(pts, pose=pose, jacobians=True)
    checked = 0
    for i, p in enumerate(pts):
        if abs(q["signed_distance"][i]) < 1e-4:
            continue  # at the boundary the closest feature may change within the step
        sd_pose = numeric_jacobian(lambda x: notched_block.query(p, pose=x)["signed_distance"], pose)
        sd_point = numeric_jacobian(lambda x: notched_block.query(x, pose=pose)["signed_distance"], p)
        cp_pose = numeric_jacobian(lambda x: notched_block.query(p, pose=x)["closest_point"][0], pose)
        if q["feature_kind"][i] == pg.EDGE:  # smooth there; at vertices the closest point is fixed anyway
            np.testing.assert_allclose(q["J_closest_pose"][i], cp_pose, atol=1e-6)
        np.testing.assert_allclose(q["J_sd_pose"][i], sd_pose, atol=1e-6)
        np.testing.assert_allclose(q["J_sd_point"][i], sd_point, atol=1e-6)
        checked += 1
    assert checked > 30


def test_shape_pairs_broadcast_and_their_jacobians(notched_block):
    pair = pg.ShapePair(notched_block, pg.Shape.disk(0.005))
    finger = np.array([[0.08, 0.0, 0.0], [0.064, 0.0, 0.0], [0.0, 0.0, 0.0]])
    r = pair.query([0.0, 0.0, 0.0], finger, jacobians=True)
    assert r["signed_distance"].shape == (3,) and r["intersecting"].dtype == np.bool_
    assert r["signed_distance"][0] == pytest.approx(0.015, abs=1e-15)
    assert r["intersecting"][2] and r["depth"][2] > 0
    np.testing.assert_allclose(r["object_point"] - r["finger_point"], -r["signed_distance"][:, None] * r["normal"], atol=1e-15)
    for i in range(2):
        num = numeric_jacobian(lambda x: pair.query([0, 0, 0], x)["signed_distance"], finger[i])
        np.testing.assert_allclose(r["J_sd_finger_pose"][i], num, atol=1e-6)
        num = numeric_jacobian(lambda x: pair.query(x, finger[i])["signed_distance"], np.zeros(3))
        np.testing.assert_allclose(r["J_sd_object_pose"][i], num, atol=1e-6)
    # A bad entry is named by row and column: a NaN heading was "pose[0] is not finite".
    bad = finger.copy()
    bad[1, 2] = np.nan
    with pytest.raises(ValueError, match=r"\[1, 2\] is nan"):
        pair.query([0.0, 0.0, 0.0], bad)
    with pytest.raises(ValueError, match="3 and 2 rows"):
        pair.query(np.zeros((3, 3)), np.zeros((2, 3)))
    # One pose beside none is none, as NumPy broadcasts (it was one row read from missing memory).
    for a, b in (((5, 5, 0), np.zeros((0, 3))), (np.zeros((0, 3)), (0, 0, 0))):
        r = pair.query(a, b)
        assert r["signed_distance"].shape == (0,) and r["finger_point"].shape == (0, 2)


def test_distance_field_within_its_measured_error(notched_block):
    field = pg.DistanceField(notched_block, resolution=2e-3)
    lo, hi = field.bounds
    pts = np.random.default_rng(11).uniform(lo, hi, (500, 2))  # inside the grid
    d, grad = field.evaluate(pts, gradient=True)
    assert grad.shape == (500, 2)
    assert field.max_error < 2e-3
    assert np.max(np.abs(d - notched_block.signed_distance(pts))) <= 2 * field.max_error + 1e-12


def test_a_mesh_footprint_in_millimetres(tmp_path):
    obj = tmp_path / "box.obj"
    obj.write_text("v 0 0 0\nv 90 0 0\nv 90 60 0\nv 0 60 0\nv 0 0 10\nv 90 0 10\nv 90 60 10\nv 0 60 10\n"
                   "f 1 2 3\nf 1 3 4\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n")
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nothing to say at the right scale
        s = pg.Shape.from_mesh(str(obj), scale=0.001)
    assert s.area == pytest.approx(0.09 * 0.06, rel=1e-12)
    # Read in the file's millimetres as metres: said as `pushgraph footprint` says it.
    with pytest.warns(UserWarning, match=r"90 m across.*is the file in millimetres \(scale=0.001"):
        pg.Shape.from_mesh(str(obj))
    empty = tmp_path / "empty.obj"
    empty.write_text("# nothing\n")
    with pytest.raises(pg.IoError, match="empty.obj"):
        pg.Shape.from_mesh(str(empty))


def test_errors_quoting_bytes_that_are_not_utf8_keep_their_message(tmp_path):
    # A file's own bytes in a message (here a Latin-1 e): the exception came with no message at all.
    latin = tmp_path / "latin.json"
    latin.write_bytes(b'{"format": "caf\xe9"}')
    with pytest.raises(pg.IoError, match="latin.json") as error:
        pg.load_trajectory(str(latin))
    assert "\ufffd" in str(error.value)
    # Warnings quoting such bytes (a group's name) are warnings, not a UnicodeDecodeError.
    groups = tmp_path / "groups.obj"
    groups.write_bytes(b"v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0.2 0 0\nv 0.3 0 0\nv 0.2 0.1 0\n"
                       b"g caf\xe9\nf 1 2 3\ng other\nf 4 5 6\n")
    with pytest.warns(UserWarning, match="holds 2 objects or groups \\(caf\ufffd, other\\)"):
        assert pg.Shape.from_mesh(str(groups)).area > 0
    # An HDF5 recording given to load_trajectory is named as such (it was "malformed JSON").
    h5 = tmp_path / "recording.h5"
    h5.write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(64))
    with pytest.raises(pg.IoError, match="recording.h5: an HDF5 file: .*read_mit_push"):
        pg.load_trajectory(str(h5))


def test_shapes_pickle_and_deepcopy(notched_block):
    # A shape survives pickling and copy.deepcopy (of a trajectory dict, say) to the last bit.
    import copy
    import pickle
    again = pickle.loads(pickle.dumps(notched_block))
    assert again.to_json() == notched_block.to_json()
    points = np.array([[0.01, 0.02], [-0.05, 0.039], [0.3, 0.0]])
    np.testing.assert_array_equal(again.signed_distance(points), notched_block.signed_distance(points))
    rounded = pg.Shape.box(0.02, 0.01, radius=0.003)
    assert copy.deepcopy({"shape": rounded})["shape"].to_json() == rounded.to_json()
