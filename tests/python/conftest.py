# Shared fixtures of the Python tests: where the project's data, the shared data and the
# command-line tool are (ctest sets them; defaults for a run from the repository root).
import os
import pathlib

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("PUSHGRAPH_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
SHARED_DIR = pathlib.Path(os.environ.get("PUSHGRAPH_SHARED_DIR", SOURCE_DIR.parent / "shared"))
TOOL = os.environ.get("PUSHGRAPH_TOOL", str(SOURCE_DIR / "build" / "tools" / "pushgraph"))


@pytest.fixture(scope="session")
def notched_block():
    import pushgraph
    return pushgraph.Shape.load_json(str(SOURCE_DIR / "data" / "shapes" / "notched_block.json"))


@pytest.fixture(scope="session")
def push(notched_block):
    import pushgraph
    return pushgraph.simulate(notched_block, pushgraph.Shape.disk(0.005), push_angle=0.7, offset=0.01, seed=3)
