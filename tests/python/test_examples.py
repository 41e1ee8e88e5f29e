# The Python examples run as a user would run them, from the build tree's package.
import os
import pathlib
import subprocess
import sys

from conftest import SOURCE_DIR


def run(script, *args):
    env = dict(os.environ)
    return subprocess.run([sys.executable, str(SOURCE_DIR / "examples" / "python" / script), *args], check=True,
                          capture_output=True, text=True, env=env).stdout


def test_estimate_push(tmp_path):
    out = run("estimate_push.py", str(tmp_path / "push.png"))
    assert "object position RMS" in out
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return
    assert (tmp_path / "push.png").stat().st_size > 10000


def test_grade_kernel():
    out = run("grade_kernel.py")
    assert "sign errors" in out and "worst |naive - exact|" in out
