"""pushgraph: geometry-exact planar contact, limit surfaces and factor-graph estimation of pushing.

The C++ library over NumPy arrays: every query takes (N, 2) points or (N, 3) poses and loops in
C++ with the GIL released; trajectories and estimates are dicts of arrays.

    import numpy as np, pushgraph

    block = pushgraph.Shape.load_json("data/shapes/notched_block.json")
    d = block.signed_distance(np.random.uniform(-0.1, 0.1, (1000, 2)))     # exact, (1000,)

    push = pushgraph.simulate(block, pushgraph.Shape.disk(0.005), seed=3)  # dict of arrays
    result = pushgraph.estimate(push, model="qs")                           # batch, with covariances
    result["object_pose"], result["object_pose_cov"], result["metrics"]["object_position_rms"]

Errors are exceptions with the C++ messages (what is wrong and where): GeometryError,
LimitSurfaceError, PushError and GraphError are ValueErrors, IoError and EvaluationError
OSErrors. docs/python.md has the
whole API.
"""
import json as _json
import math as _math
import operator as _operator
import os as _os

from . import _pushgraph
from ._pushgraph import (  # noqa: F401  (re-exported)
    EDGE,
    INSIDE,
    ON_BOUNDARY,
    OUTSIDE,
    VERTEX,
    DistanceField,
    EvaluationError,
    GeometryError,
    GraphError,
    IoError,
    LimitSurface,
    LimitSurfaceError,
    PushError,
    Shape,
    ShapePair,
    load_trajectory,
    read_mit_push,
    save_trajectory,
    simulate,
)

__version__ = "0.1.0"

MODELS = ("cp", "sdf", "qs", "yu")
MODES = ("batch", "incremental")


def _config_json(config):
    """An estimator configuration as JSON text: None, a dict of config keys, or a path to a JSON file."""
    if config is None:
        return ""
    if isinstance(config, dict):
        # NumPy scalars and arrays (np.int64(20), np.float32(0.5)) as the Python numbers they hold;
        # anything else that is no JSON value is named with its key.
        def plain(value):
            if hasattr(value, "tolist"):
                return value.tolist()
            raise TypeError("a value of type %s is not a JSON value (numbers, strings, booleans, None, lists and dicts of them)"
                            % type(value).__name__)
        parts = []
        for key, value in config.items():
            if not isinstance(key, str):
                raise TypeError("config: the key %r is not a string (config keys are names, docs/estimation.md)" % (key,))
            try:
                parts.append("%s: %s" % (_json.dumps(key), _json.dumps(value, default=plain)))
            except (TypeError, ValueError) as e:
                raise TypeError("config[%r]: %s" % (key, e)) from None
        return "{" + ", ".join(parts) + "}"
    if isinstance(config, (str, bytes, _os.PathLike)):
        with open(config, "r", encoding="utf-8") as f:
            return f.read()
    raise TypeError("config: expected None, a dict of estimator config keys or a path to a JSON file, got %s"
                    % type(config).__name__)


def estimate(trajectory, model="qs", mode="batch", config=None, apply_measurement_sigmas=True):
    """Estimates a push: object and finger poses, contact points and forces, with covariances.

    trajectory: a dict as load_trajectory, simulate or read_mit_push return.
    model: "cp", "sdf", "qs" (the default) or "yu" (the Yu-Rodriguez baseline).
    mode: "batch" or "incremental" (fixed-lag smoothing).
    config: estimator configuration keys (docs/estimation.md) as a dict or a JSON file path,
        for example {"solver": "chain", "incremental_update_every_steps": 1}.
    apply_measurement_sigmas: use the trajectory's measurement_sigmas (when it has them) as the
        measurement factors' sigmas, as `pushgraph estimate` does.

    Returns a dict: t (N,), object_pose and finger_pose (N, 3), contact and force (N, 2; NaN
    where the state has none), their covariances (N, 3, 3) / (N, 2, 2) (NaN when absent),
    metrics (RMS errors and NEES against ground truth), warnings, solver (name, iterations,
    times, update_times_s), c, c_sigma, mu, mu_sigma, and RESULT.json's parameters (the shape
    transform applied, c, mu), shape (the shape check) and diagnostics with the file's keys (None
    when absent). Raises GraphError naming the bad input.
    """
    if model not in MODELS:
        raise GraphError("model: expected one of %s, got %r" % (", ".join(MODELS), model))
    if mode not in MODES:
        raise GraphError("mode: expected one of %s, got %r" % (", ".join(MODES), mode))
    return _pushgraph._estimate(trajectory, model, mode, _config_json(config), bool(apply_measurement_sigmas))


def evaluate(inputs=(), protocols="all", simulate=0, sim_object=None, sim_finger=None, sim_mass=0.5, sim_mu=0.3,
             sim_mu_contact=0.4, seed=1, jobs=0, mesh_dir="", estimator_config=None):
    """The paper's evaluation protocols, as `pushgraph evaluate` runs them (docs/evaluation.md).

    inputs: MIT recordings (.h5), trajectory files or folders of them; simulate: also that many
    seeded simulated pushes of sim_object by sim_finger (pushgraph.Shape). protocols: "all" or a
    comma list (table1, table2, fig5, occlusion, consistency, runtime). jobs: worker threads (0:
    all cores). Returns {"tables": [{"id", "title", "columns", "rows": [dict per row], "notes"}],
    "trajectories": [{"name", "group", "error", "stats", "notes"}], "notes": [...]}.
    """
    if isinstance(inputs, (str, bytes, _os.PathLike)):
        inputs = [inputs]
    return _pushgraph._evaluate([_os.fspath(i) for i in inputs], protocols, int(simulate), sim_object, sim_finger,
                                float(sim_mass), float(sim_mu), float(sim_mu_contact), int(seed), int(jobs),
                                _os.fspath(mesh_dir), _config_json(estimator_config))


def _sample_time(t):
    # float() reads '0.5' and True as times; the docs' rule (docs/python.md) is a TypeError.
    if isinstance(t, (str, bytes, bool)) or type(t).__name__ == "bool_":  # numpy.bool_ is no bool
        raise TypeError(f"a sample's time must be a number of seconds, not {type(t).__name__} {t!r}")
    return float(t)


def _finger_index(finger, fingers):
    # bool and numpy.bool_ are not indices (numpy.bool_ passes operator.index).
    have = "finger 0 only" if fingers == 1 else "fingers 0 to %d" % (fingers - 1)
    expected = "0" if fingers == 1 else "0 to %d" % (fingers - 1)
    if isinstance(finger, bool) or type(finger).__name__ in ("bool_", "bool"):
        raise TypeError("finger: expected an integer index (%s), got %r" % (expected, finger))
    try:
        index = _operator.index(finger)
    except TypeError:
        raise TypeError("finger: expected an integer index (%s), got %r" % (expected, finger)) from None
    if not -2**31 <= index < 2**31:  # beyond C++'s int: out of range like any other index
        raise GraphError("finger %d is out of range: the setup has %s" % (index, have))
    return index


class OnlineEstimator:
    """The fixed-lag smoother for a running robot, fed one sample at a time.

        online = pushgraph.OnlineEstimator(setup, model="qs", force=True)
        for t, pose in camera:   online.add_object_pose(t, pose)      # (x, y, theta)
        ...                      online.add_finger_pose(t, pose); online.add_force(t, (fx, fy))
        if online.update_due(): online.update(); online.latest_state()["object_pose"]
        result = online.finish()                                       # as estimate() returns

    setup: a trajectory dict whose streams may be empty (object and finger descriptions);
    contact_point, force: which sensors will report (they decide contact gating and the
    limit-surface load factor). Each add_* returns False when the sample came too late (at or
    before the last update) and was dropped, or was left out as a sensor fault (a tracker glitch
    far from the poses before it, a contact row far off its finger, a force spike; counted by
    dropped_faulty_samples, the first of each kind named in finish()'s warnings); samples out of
    order, not finite or beyond 1e6 m / 1e9 N raise GraphError (the estimator goes on).
    Several fingers: setup["fingers"] holds fingers 1, 2, ... (their streams empty); their samples
    come with finger=k (each finger's sensors are the kinds declared), and latest_state() has
    finger1_pose, finger2_pose, ... and every contact with its finger.
    """

    def __init__(self, setup, model="qs", config=None, contact_point=False, force=True, max_latency=0.2):
        if model not in MODELS:
            raise GraphError("model: expected one of %s, got %r" % (", ".join(MODELS), model))
        self._core = _pushgraph._OnlineEstimator(setup, model, _config_json(config), bool(contact_point), bool(force),
                                                 float(max_latency))
        self._fingers = 1 + len(setup.get("fingers") or ())

    def add_object_pose(self, t, pose):
        return self._core.add_object_pose(_sample_time(t), pose)

    def add_finger_pose(self, t, pose, finger=0):
        return self._core.add_finger_pose(_sample_time(t), pose, _finger_index(finger, self._fingers))

    def add_contact_point(self, t, point, finger=0):
        return self._core.add_contact_point(_sample_time(t), point, _finger_index(finger, self._fingers))

    def add_force(self, t, force, finger=0):
        return self._core.add_force(_sample_time(t), force, _finger_index(finger, self._fingers))

    def update_due(self):
        return self._core.update_due()

    def update(self, until=_math.inf):
        """Solves the window up to `until` (default: where every live stream has reported); returns its wall time (s)."""
        return self._core.update(float(until))

    def latest_state(self):
        """The newest state: dict with t, object_pose, finger_pose, contact and force (finger 0's; None
        when absent), contacts (every contact: dicts of finger, point, force), and fingerK_pose of
        each finger K >= 1 of a push with several."""
        return self._core.latest_state()

    @property
    def dropped_late_samples(self):
        return self._core.dropped_late_samples

    @property
    def dropped_faulty_samples(self):
        return self._core.dropped_faulty_samples

    def warnings(self):
        """What is wrong with the setup so far, as sentences (finish() repeats them): the object's
        shape is checked against the contacts as estimate() does. A shape that fits in other units
        alone (a CAD file in millimetres) is read in them from then on; one turned or shifted off
        the tracker's frame is named with the placement the contacts prefer, not applied."""
        return self._core.warnings()

    def finish(self):
        """Every step's estimate, as estimate() returns it. Call once."""
        return self._core.finish()
