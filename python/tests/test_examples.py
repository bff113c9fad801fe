"""The examples in examples/, run as a user would (coarser tissue, to be quick)."""
import os
import subprocess
import sys

from conftest import BINARY, ROOT


def run_example(name, *args, cwd=None):
    env = dict(os.environ, PYTHONPATH=str(BINARY / "python"))
    return subprocess.run([sys.executable, str(ROOT / "examples" / name), *args], env=env,
                          capture_output=True, text=True, cwd=cwd)


def test_force_probe_holds_a_tenth_of_a_newton():
    r = run_example("force_probe.py", "--spacing", "0.004", "--steps", "2500")
    assert r.returncode == 0, r.stdout + r.stderr
    words = r.stdout.split()
    held = float(words[words.index("holds") + 1])
    assert abs(held - 0.1) < 0.005, r.stdout


def test_scripted_resection_frees_the_top_of_the_block():
    r = run_example("scripted_resection.py", "--spacing", "0.004")
    assert r.returncode == 0, r.stdout + r.stderr
    # "... the cut freed P piece(s), F g of T g; ...": the slice above 12 mm of the 20 mm block.
    words = r.stdout.split()
    at = words.index("freed")
    freed, total = float(words[at + 3]), float(words[at + 6])
    assert 0.3 < freed / total < 0.55, r.stdout


def test_render_video_writes_an_mp4(tmp_path):
    out = tmp_path / "v.mp4"
    r = run_example("render_video.py", "--spacing", "0.006", "--frames", "4", "--every", "20",
                    "--width", "160", "--height", "96", "--out", str(out))
    assert r.returncode == 0, r.stdout + r.stderr
    data = out.read_bytes()
    assert data[4:8] == b"ftyp" and len(data) > 1000
