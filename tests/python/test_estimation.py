# Trajectories, the simulator, the MIT reader and estimation from Python: the numbers the C++
# tool writes to the last bit, the incremental and online modes, errors, threads.
import concurrent.futures
import json
import subprocess

import numpy as np
import pytest

import pushgraph as pg
from conftest import SHARED_DIR, TOOL


def test_trajectory_round_trip(push, tmp_path):
    m = push["measured"]
    assert m["object_pose"]["pose"].shape[1] == 3 and m["force"]["force"].shape[1] == 2
    assert push["ground_truth"] is not None and push["measurement_sigmas"]["object_trans"] > 0
    path = tmp_path / "push.json"
    pg.save_trajectory(push, str(path))
    again = pg.load_trajectory(str(path))
    for stream, value in [("object_pose", "pose"), ("finger_pose", "pose"), ("contact_point", "point"), ("force", "force")]:
        np.testing.assert_array_equal(again["measured"][stream]["t"], m[stream]["t"])
        np.testing.assert_array_equal(again["measured"][stream][value], m[stream][value])
    assert again["object"]["mass"] == push["object"]["mass"]


def test_paths_and_repaired_rows(push, tmp_path):
    # pathlib.Path as well as str (helper-27 N8: "incompatible function arguments"); rows the
    # reader sorted come as a UserWarning (N9: sorted silently).
    path = tmp_path / "push.json"
    pg.save_trajectory(push, path)
    again = pg.load_trajectory(path)
    np.testing.assert_array_equal(again["measured"]["object_pose"]["t"], push["measured"]["object_pose"]["t"])
    shape_path = tmp_path / "box.json"
    pg.Shape.box(0.09, 0.05).save_json(shape_path)
    assert pg.Shape.load_json(shape_path).area == pytest.approx(0.09 * 0.05)
    data = json.loads(path.read_text())
    rows = data["streams"]["object_pose"]
    rows[1], rows[2] = rows[2], rows[1]
    swapped = tmp_path / "swapped.json"
    swapped.write_text(json.dumps(data))
    with pytest.warns(UserWarning, match="object_pose"):
        sorted_again = pg.load_trajectory(swapped)
    np.testing.assert_array_equal(sorted_again["measured"]["object_pose"]["t"], push["measured"]["object_pose"]["t"])


def test_bad_trajectory_dicts_name_the_key(push):
    bad = dict(push)
    bad["measured"] = dict(push["measured"], camera={"t": [0.0], "pose": [[0, 0, 0]]})
    with pytest.raises(ValueError, match="unknown stream 'camera'"):
        pg.estimate(bad)
    bad = dict(push)
    bad["measured"] = dict(push["measured"], force={"t": [0.0, 1.0], "force": [[0, 0]]})
    with pytest.raises(ValueError, match="2 times and 1 values"):
        pg.estimate(bad)
    with pytest.raises(TypeError, match="expected a dict"):
        pg.estimate([1, 2, 3])
    heavy = dict(push, object=dict(push["object"], mass=True))
    with pytest.raises(TypeError, match=r"\['mass'\]: expected a number, not a boolean"):
        pg.estimate(heavy)
    with pytest.raises(pg.GraphError, match="model"):
        pg.estimate(push, model="qs2")
    with pytest.raises(pg.GraphError, match="sigma_typo"):
        pg.estimate(push, config={"sigma_typo": 1})
    unsorted = dict(push)
    unsorted["measured"] = dict(push["measured"])
    op = push["measured"]["object_pose"]
    unsorted["measured"]["object_pose"] = {"t": op["t"][::-1].copy(), "pose": op["pose"][::-1].copy()}
    with pytest.raises(pg.GraphError):
        pg.estimate(unsorted)


def test_measurement_sigmas_take_the_trajectory_files_keys_too(push):
    s = push["measurement_sigmas"]
    as_in_file = dict(push, measurement_sigmas={"object_pose": [s["object_trans"], s["object_rot"]],
                                                "finger_pose": [s["finger_trans"], s["finger_rot"]],
                                                "contact_point": s["contact"], "force": s["force"]})
    config = {"covariance": False, "diagnostics": False}
    a, b = pg.estimate(push, config=config), pg.estimate(as_in_file, config=config)
    np.testing.assert_array_equal(a["object_pose"], b["object_pose"])
    np.testing.assert_array_equal(a["force"], b["force"])
    with pytest.raises(ValueError, match="trajectory file's keys.*unknown key 'contact'"):
        pg.estimate(dict(push, measurement_sigmas={"object_pose": [0.005, 0.05], "contact": 0.001}))
    with pytest.raises(ValueError, match=r"\[sigma_trans, sigma_rot\], got 1"):
        pg.estimate(dict(push, measurement_sigmas={"object_pose": [0.005]}))


def test_batch_estimate_equals_the_command_line_tool_to_the_last_bit(push, tmp_path):
    path = tmp_path / "push.json"
    pg.save_trajectory(push, str(path))
    out = tmp_path / "result.json"
    subprocess.run([TOOL, "estimate", str(path), "--model", "qs", "-o", str(out)], check=True, capture_output=True)
    cli = json.load(open(out))
    r = pg.estimate(pg.load_trajectory(str(path)), model="qs")
    assert len(cli["states"]) == len(r["t"])
    for i, s in enumerate(cli["states"]):
        assert s["t"] == r["t"][i]
        assert s["object_pose"] == list(r["object_pose"][i])
        assert s["finger_pose"] == list(r["finger_pose"][i])
        if "force" in s:
            assert s["force"] == list(r["force"][i])
        else:
            assert np.all(np.isnan(r["force"][i]))
        assert np.array(s["object_pose_cov"]).tolist() == r["object_pose_cov"][i].tolist()
    assert cli["metrics"]["object_position_rms"] == r["metrics"]["object_position_rms"]
    assert r["metrics"]["object_position_rms"] < 0.3 * r["metrics"]["measured_object_position_rms"]
    # RESULT.json's parameters, shape check and self-diagnosis, with its keys.
    for key in ("parameters", "shape", "diagnostics"):
        assert r[key] == cli.get(key), key
    assert r["shape"]["checked"] and r["parameters"]["c"] > 0


def test_incremental_every_step_and_the_chain_solver(push):
    batch = pg.estimate(push, model="qs")
    inc = pg.estimate(push, model="qs", mode="incremental",
                      config={"solver": "chain", "incremental_update_every_steps": 5, "covariance": False})
    assert inc["solver"]["name"] == "chain"
    assert inc["solver"]["update_times_s"].shape == (inc["solver"]["updates"],)
    assert np.all(inc["solver"]["update_times_s"] > 0)
    assert np.all(np.isnan(inc["object_pose_cov"]))
    assert inc["metrics"]["object_position_rms"] < 1.1 * batch["metrics"]["object_position_rms"]
    # NumPy numbers in a config dict are the numbers they hold; other values are named by key.
    again = pg.estimate(push, model="qs", mode="incremental",
                        config={"solver": "chain", "incremental_update_every_steps": np.int64(5), "covariance": np.bool_(False)})
    assert again["metrics"]["object_position_rms"] == inc["metrics"]["object_position_rms"]
    with pytest.raises(TypeError, match="config\\['max_iterations'\\]: a value of type object is not a JSON value"):
        pg.estimate(push, config={"max_iterations": object()})


def test_online_estimator_fed_from_python(push):
    setup = {"object": push["object"], "finger": push["finger"],
             "measured": {}, "measurement_sigmas": push["measurement_sigmas"]}
    online = pg.OnlineEstimator(setup, model="qs", contact_point=True, force=True)
    with pytest.raises(pg.GraphError, match="no step estimated yet"):
        online.latest_state()
    m = push["measured"]
    samples = []
    for stream, value in [("object_pose", "pose"), ("finger_pose", "pose"), ("contact_point", "point"), ("force", "force")]:
        for t, v in zip(m[stream]["t"], m[stream][value]):
            samples.append((t, stream, v))
    samples.sort(key=lambda s: s[0])
    add = {"object_pose": online.add_object_pose, "finger_pose": online.add_finger_pose,
           "contact_point": online.add_contact_point, "force": online.add_force}
    updates = 0
    for k, (t, stream, v) in enumerate(samples):
        add[stream](t, v)
        if (k + 1 == len(samples) or samples[k + 1][0] > t) and online.update_due():
            online.update()
            updates += 1
            state = online.latest_state()
            assert len(state["object_pose"]) == 3
    with pytest.raises(pg.GraphError, match="not after the previous"):
        online.add_force(0.0, (1.0, 0.0))
    # A non-finite value is a GraphError naming the stream and time (it was a bare ValueError).
    with pytest.raises(pg.GraphError, match=r"streams\.finger_pose\[\d+\] at t = .* is not finite"):
        online.add_finger_pose(1e3, (np.nan, 0.0, 0.0))
    result = online.finish()
    assert updates > 3 and len(result["t"]) > 100
    assert np.all(np.isfinite(result["object_pose"]))
    assert online.warnings() == []


def feed_online(push, **streams):
    """The push's samples in time order into an OnlineEstimator, updating when due; its result."""
    setup = {"object": push["object"], "finger": push["finger"], "measured": {},
             "measurement_sigmas": push["measurement_sigmas"], "ground_truth": push["ground_truth"]}
    online = pg.OnlineEstimator(setup, model="qs", contact_point=True, force=True, **streams)
    m = push["measured"]
    samples = sorted(((t, stream, v) for stream, value in [("object_pose", "pose"), ("finger_pose", "pose"),
                                                             ("contact_point", "point"), ("force", "force")]
                      for t, v in zip(m[stream]["t"], m[stream][value])), key=lambda s: s[0])
    add = {"object_pose": online.add_object_pose, "finger_pose": online.add_finger_pose,
           "contact_point": online.add_contact_point, "force": online.add_force}
    for k, (t, stream, v) in enumerate(samples):
        add[stream](t, v)
        if (k + 1 == len(samples) or samples[k + 1][0] > t) and online.update_due():
            online.update()
    result = online.finish()
    result["dropped_faulty_samples"] = online.dropped_faulty_samples
    return result


def test_online_fault_guards_keep_good_samples(notched_block):
    """The online guards against tracker glitches and corrupt contact rows take nothing good: a fast
    push from rest with a precise tracker (0.3 s of poses were refused at its onset), a 20 Hz finger
    at 0.5 m/s (contact rows judged against its stale pose); and a contact stream 5 cm off is left
    out by the contact check, not row by row (each row was refused, and the check never ran)."""
    finger = pg.Shape.disk(0.005)
    fast = pg.simulate(notched_block, finger, speed=0.4, distance=0.3, standoff=0.18, object_rate=20.0, seed=3,
                       sigmas={"object": (0.0005, 0.005)})
    coarse = pg.simulate(notched_block, finger, speed=0.5, distance=0.3, finger_rate=20.0, seed=3)
    for push in (fast, coarse):
        result = feed_online(push)
        assert not [w for w in result["warnings"] if "sensor faults" in w], result["warnings"]
        assert result["dropped_faulty_samples"] == 0
        assert np.all(np.isfinite(result["object_pose"]))
    with pytest.raises(TypeError, match=r"sigmas\['finger'\]: expected one number"):
        pg.simulate(notched_block, finger, sigmas={"finger": (0.0005, 0.0)})
    off = pg.simulate(notched_block, finger, seed=3, sigmas={"contact": 0.001, "finger": 0.0005})
    off["measured"]["contact_point"]["point"][:, 0] += 0.05
    result = feed_online(off)
    assert [w for w in result["warnings"] if "contact check (OnlineEstimator" in w], result["warnings"]
    assert not [w for w in result["warnings"] if "contact_point row" in w], result["warnings"]


def test_online_estimator_names_a_shape_in_millimetres(push):
    setup = {"object": dict(push["object"]), "finger": push["finger"], "measured": {}}
    setup["object"]["shape"] = push["object"]["shape"].transformed(scale=1000.0)
    online = pg.OnlineEstimator(setup, model="qs", config={"covariance": False}, contact_point=True, force=True)
    m = push["measured"]
    samples = [(t, stream, v) for stream, value in [("object_pose", "pose"), ("finger_pose", "pose"),
                                                    ("contact_point", "point"), ("force", "force")]
               for t, v in zip(m[stream]["t"], m[stream][value])]
    samples.sort(key=lambda s: (s[0], s[1]))
    add = {"object_pose": online.add_object_pose, "finger_pose": online.add_finger_pose,
           "contact_point": online.add_contact_point, "force": online.add_force}
    said = None
    for k, (t, stream, v) in enumerate(samples):
        add[stream](t, v)
        if (k + 1 == len(samples) or samples[k + 1][0] > t) and online.update_due():
            online.update()
            if said is None and any(w.startswith("shape check") for w in online.warnings()):
                said = t
    assert said is not None and said < samples[-1][0]  # during the push
    # Said from the start (no tabletop object reaches 1 m), then read in its units by the shape check.
    size, warning = online.warnings()
    assert "which no tabletop object does" in size
    assert "does not fit the contacts as given" in warning and "millimetres" in warning
    result = online.finish()  # checked once more on every sample: the same finding, its placement refined
    print(online.warnings())
    assert len(online.warnings()) == 2 and "millimetres" in online.warnings()[1]
    assert result["warnings"][:2] == online.warnings()


def test_estimates_run_in_threads(push):
    config = {"covariance": False, "diagnostics": False}
    alone = [pg.estimate(push, model=m, config=config) for m in ("cp", "qs")]
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        together = list(pool.map(lambda m: pg.estimate(push, model=m, config=config), ("cp", "qs")))
    for a, b in zip(alone, together):
        np.testing.assert_array_equal(a["object_pose"], b["object_pose"])


def test_mit_recording():
    f = SHARED_DIR / "data/mit-push/abs/rect1/motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.800_t=0.349.h5"
    if not f.exists():
        pytest.skip("no MIT data at %s" % f)
    t, fault = pg.read_mit_push(str(f), pg.Shape.box(0.09, 0.09), 0.8374, 0.35, pg.Shape.disk(0.00235))
    assert "frozen" in fault and t["measured"]["force"]["t"].size == 0
    assert t["measured"]["object_pose"]["t"].size > 100
    with pytest.raises(pg.IoError, match="nothing.h5"):
        pg.read_mit_push(str(f.parent / "nothing.h5"), pg.Shape.box(0.09, 0.09), 0.8, 0.35, pg.Shape.disk(0.00235))
    # The tool's bounds on mass and frictions (they also set the contact phase's threshold).
    for mass, mu, name in ((-1.0, 0.35, "mass"), (1e9, 0.35, "mass"), (0.8, float("nan"), "mu_surface"),
                           (0.8, -5.0, "mu_surface")):
        with pytest.raises(ValueError, match="read_mit_push: %s = " % name):
            pg.read_mit_push(str(f), pg.Shape.box(0.09, 0.09), mass, mu, pg.Shape.disk(0.00235))


def test_evaluation_tables_as_dicts(notched_block):
    out = pg.evaluate(simulate=2, sim_object=notched_block, sim_finger=pg.Shape.disk(0.005), protocols="table1,runtime",
                      jobs=2)
    ids = [t["id"] for t in out["tables"]]
    assert "table1" in ids and "runtime" in ids
    table1 = next(t for t in out["tables"] if t["id"] == "table1")
    assert table1["rows"] and set(table1["columns"]) == set(table1["rows"][0])
    assert len(out["trajectories"]) == 2 and all(t["error"] == "" for t in out["trajectories"])
    with pytest.raises(pg.GraphError, match="nothing to evaluate"):
        pg.evaluate()
    with pytest.raises(ValueError, match="sim_object"):
        pg.evaluate(simulate=1)


def test_simulate_along_waypoints_with_chosen_noise_and_an_occlusion(notched_block):
    finger = pg.Shape.disk(0.005)
    t = pg.simulate(notched_block, finger, waypoints=[[-0.08, 0.0], [0.0, 0.0]], sigmas={"object": (0.005, 0.05), "force": 0.5},
                    occlusions=[[0.5, 0.9]], seed=2)
    assert t["measurement_sigmas"]["object_trans"] == 0.005 and t["measurement_sigmas"]["force"] == 0.5
    ts = t["measured"]["object_pose"]["t"]
    assert not np.any((ts > 0.5) & (ts < 0.9)) and np.any(ts > 0.9)
    with pytest.raises(ValueError, match="unknown key 'camera'"):
        pg.simulate(notched_block, finger, sigmas={"camera": 0.1})
    with pytest.raises(ValueError, match="noise is 'none'"):
        pg.simulate(notched_block, finger, noise="none", sigmas={"force": 0.1})
    with pytest.raises(pg.PushError):
        pg.simulate(notched_block, finger, waypoints=[[0.0, 0.0]])


def test_two_fingers_round_trip_and_estimate(tmp_path):
    # A two-finger push made by the tool (two 4 mm disks 4 cm apart), read, written back and
    # estimated from Python: finger 1's pose and contact come back, the same as the tool's.
    (tmp_path / "left.json").write_text('{"polygons": [{"outer": [[0, 0.02]]}], "radius": 0.004}')
    (tmp_path / "right.json").write_text('{"polygons": [{"outer": [[0, -0.02]]}], "radius": 0.004}')
    path, out = tmp_path / "two.json", tmp_path / "two_result.json"
    subprocess.run([TOOL, "simulate", "-o", str(path), "--fingers", str(tmp_path / "left.json"),
                    str(tmp_path / "right.json"), "--offset", "0", "--push-angle", "0"], check=True, capture_output=True)
    push = pg.load_trajectory(str(path))
    assert len(push["fingers"]) == 1 and "object_pose" not in push["fingers"][0]["measured"]
    again_path = tmp_path / "again.json"
    pg.save_trajectory(push, str(again_path))
    again = pg.load_trajectory(str(again_path))
    f, g = push["fingers"][0]["measured"], again["fingers"][0]["measured"]
    for stream, value in [("finger_pose", "pose"), ("contact_point", "point"), ("force", "force")]:
        np.testing.assert_array_equal(g[stream][value], f[stream][value])
    nan_force = {**push, "fingers": [{**push["fingers"][0], "measured": {**f, "force": {**f["force"], "force": f["force"]["force"].copy()}}}]}
    nan_force["fingers"][0]["measured"]["force"]["force"][11, 1] = np.nan
    with pytest.raises(OSError, match=r"fingers\[1\]\.force\[11\] is not finite"):
        pg.save_trajectory(nan_force, str(tmp_path / "nan.json"))
    assert not (tmp_path / "nan.json").exists()
    r = pg.estimate(push, model="qs")
    assert r["finger1_pose"].shape == r["object_pose"].shape and np.isfinite(r["finger1_pose"]).all()
    touching = np.isfinite(r["second_contact"][:, 0])
    assert touching.sum() > 100 and np.isfinite(r["contact_forces"][touching, 1]).all()
    subprocess.run([TOOL, "estimate", str(path), "--model", "qs", "-o", str(out)], check=True, capture_output=True)
    states = json.loads(out.read_text())["states"]
    np.testing.assert_array_equal(r["finger1_pose"], [s["fingers"][0]["pose"] for s in states])
    assert r["metrics"]["object_position_rms"] < r["metrics"]["measured_object_position_rms"]
    bad = dict(push, fingers=[dict(push["fingers"][0], measured=dict(f, object_pose=push["measured"]["object_pose"]))])
    with pytest.raises(ValueError, match=r"trajectory\['fingers'\]\[0\]\['measured'\]: a finger's streams have no 'object_pose'"):
        pg.estimate(bad)


def test_two_fingers_online_from_python(tmp_path):
    # The same push fed sample by sample with each finger's index: finger 1's pose is in every
    # newest state, and the result has finger 1 as estimate() gives it.
    (tmp_path / "left.json").write_text('{"polygons": [{"outer": [[0, 0.02]]}], "radius": 0.004}')
    (tmp_path / "right.json").write_text('{"polygons": [{"outer": [[0, -0.02]]}], "radius": 0.004}')
    path = tmp_path / "two.json"
    subprocess.run([TOOL, "simulate", "-o", str(path), "--fingers", str(tmp_path / "left.json"),
                    str(tmp_path / "right.json"), "--offset", "0", "--push-angle", "0"], check=True, capture_output=True)
    push = pg.load_trajectory(str(path))
    finger1 = push["fingers"][0]
    setup = {"object": push["object"], "finger": push["finger"], "measured": {},
             "measurement_sigmas": push["measurement_sigmas"],
             "fingers": [{"shape": finger1["shape"], "mu_contact": finger1["mu_contact"], "measured": {}}]}
    has_contact = "contact_point" in push["measured"]
    online = pg.OnlineEstimator(setup, model="qs", contact_point=has_contact, force=True)
    add = {"object_pose": online.add_object_pose, "finger_pose": online.add_finger_pose,
           "contact_point": online.add_contact_point, "force": online.add_force}
    samples = []
    for finger, streams in [(0, push["measured"]), (1, finger1["measured"])]:
        for stream, value in [("object_pose", "pose"), ("finger_pose", "pose"), ("contact_point", "point"), ("force", "force")]:
            if stream not in streams or (finger == 1 and stream == "object_pose"):
                continue
            for t, v in zip(streams[stream]["t"], streams[stream][value]):
                samples.append((t, finger, stream, v))
    samples.sort(key=lambda s: (s[0], s[1]))
    updates = 0
    for k, (t, finger, stream, v) in enumerate(samples):
        if stream == "object_pose":
            add[stream](t, v)
        else:
            add[stream](t, v, finger=np.int64(finger))
        if (k + 1 == len(samples) or samples[k + 1][0] > t) and online.update_due():
            online.update()
            updates += 1
            assert len(online.latest_state()["finger1_pose"]) == 3
    for far in (2, 10**30):
        with pytest.raises(pg.GraphError, match="finger %d is out of range" % far):
            online.add_force(samples[-1][0] + 1.0, (0.1, 0.0), finger=far)
    for bad in (1.0, True, np.bool_(True)):
        with pytest.raises(TypeError, match="finger: expected an integer"):
            online.add_force(samples[-1][0] + 1.0, (0.1, 0.0), finger=bad)
    for bad in ("100.0", True, np.bool_(True), b"1"):
        with pytest.raises(TypeError, match="a sample's time must be a number"):
            online.add_object_pose(bad, (0.0, 0.0, 0.0))
    r = online.finish()
    assert updates > 3
    assert r["finger1_pose"].shape == r["object_pose"].shape and np.isfinite(r["finger1_pose"]).all()
    assert np.isfinite(r["second_contact"][:, 0]).sum() > 100
    # The replay of the recording at the same update times (every 5 object samples).
    replay = pg.estimate(push, model="qs", mode="incremental")
    np.testing.assert_allclose(r["object_pose"], replay["object_pose"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(r["finger1_pose"], replay["finger1_pose"], rtol=0, atol=1e-9)


def test_three_fingers_batch_and_online(tmp_path):
    # Three 4 mm disks 2.5 cm apart pushing the notched block's side face together: every finger's
    # pose, contact and force come back (fingerK_pose, fingerK_contact, fingerK_force), online with
    # finger=2 as in batch, and latest_state() lists every contact with its finger.
    names = []
    for k, y in enumerate((0.025, 0.0, -0.025)):
        names.append(str(tmp_path / ("f%d.json" % k)))
        (tmp_path / ("f%d.json" % k)).write_text('{"polygons": [{"outer": [[0, %g]]}], "radius": 0.004}' % y)
    path = tmp_path / "three.json"
    subprocess.run([TOOL, "simulate", "-o", str(path), "--fingers", *names, "--offset", "0", "--push-angle", "0"],
                   check=True, capture_output=True)
    push = pg.load_trajectory(str(path))
    assert len(push["fingers"]) == 2
    r = pg.estimate(push, model="qs")
    assert r["metrics"]["object_position_rms"] < 0.6 * r["metrics"]["measured_object_position_rms"]
    for k in (1, 2):
        assert np.isfinite(r["finger%d_pose" % k]).all() and r["finger%d_pose_cov" % k].shape == (len(r["t"]), 3, 3)
        touching = np.isfinite(r["finger%d_contact" % k][:, 0])
        assert touching.sum() > 100 and np.isfinite(r["finger%d_force" % k][touching]).all()
        assert np.isfinite(r["finger%d_contact_cov" % k][touching]).all() and np.isfinite(r["finger%d_force_cov" % k][touching]).all()
    setup = {"object": push["object"], "finger": push["finger"], "measured": {},
             "measurement_sigmas": push["measurement_sigmas"],
             "fingers": [{"shape": f["shape"], "mu_contact": f["mu_contact"], "measured": {}} for f in push["fingers"]]}
    online = pg.OnlineEstimator(setup, model="qs", contact_point="contact_point" in push["measured"], force=True)
    add = {"finger_pose": online.add_finger_pose, "contact_point": online.add_contact_point, "force": online.add_force}
    samples = [(t, 0, "object_pose", v) for t, v in zip(push["measured"]["object_pose"]["t"], push["measured"]["object_pose"]["pose"])]
    for finger, streams in enumerate([push["measured"]] + [f["measured"] for f in push["fingers"]]):
        for stream, value in [("finger_pose", "pose"), ("contact_point", "point"), ("force", "force")]:
            if stream in streams:
                samples += [(t, finger, stream, v) for t, v in zip(streams[stream]["t"], streams[stream][value])]
    samples.sort(key=lambda s: (s[0], s[1], s[2] != "object_pose"))
    fingers_seen = set()
    for k, (t, finger, stream, v) in enumerate(samples):
        if stream == "object_pose":
            online.add_object_pose(t, v)
        else:
            add[stream](t, v, finger=finger)
        if (k + 1 == len(samples) or samples[k + 1][0] > t) and online.update_due():
            online.update()
            state = online.latest_state()
            assert len(state["finger2_pose"]) == 3
            fingers_seen |= {c["finger"] for c in state["contacts"]}
    assert fingers_seen == {0, 1, 2}
    for far in (3, 2**40):
        with pytest.raises(pg.GraphError, match="finger %d is out of range: the setup has fingers 0 to 2" % far):
            online.add_force(samples[-1][0] + 1.0, (0.1, 0.0), finger=far)
    with pytest.raises(TypeError, match=r"finger: expected an integer index \(0 to 2\), got 1.5"):
        online.add_force(samples[-1][0] + 1.0, (0.1, 0.0), finger=1.5)
    done = online.finish()
    replay = pg.estimate(push, model="qs", mode="incremental")
    np.testing.assert_allclose(done["finger2_pose"], replay["finger2_pose"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(done["object_pose"], replay["object_pose"], rtol=0, atol=1e-9)
