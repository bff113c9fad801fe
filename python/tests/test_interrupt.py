"""A Ctrl-C interrupts a long advance cleanly: KeyboardInterrupt after the current advance, the
simulation still usable."""
import json
import os
import signal
import subprocess
import sys
import textwrap
import time

from conftest import BINARY, PROBE_SCENE

CHILD = textwrap.dedent("""
    import json, sys, time
    import phyxel
    scene = json.loads(sys.argv[1])
    del scene["tools"]
    sim = phyxel.Simulation(scene, threads=1)
    print("ready", flush=True)
    try:
        sim.advance(10**9)
        print("finished", flush=True)
    except KeyboardInterrupt:
        done = sim.steps_done
        sim.advance(3)
        assert sim.steps_done == done + 3
        print("interrupted", done, flush=True)
""")


def test_ctrl_c_interrupts_a_long_advance():
    env = dict(os.environ, PYTHONPATH=str(BINARY / "python"))
    child = subprocess.Popen([sys.executable, "-c", CHILD, json.dumps(PROBE_SCENE)],
                             stdout=subprocess.PIPE, text=True, env=env)
    assert child.stdout.readline().strip() == "ready"
    time.sleep(1.0)
    child.send_signal(signal.SIGINT)
    out, _ = child.communicate(timeout=120)  # a few advances, not the 10**9 steps
    assert child.returncode == 0
    words = out.split()
    assert words[0] == "interrupted" and 0 < int(words[1]) < 10**9
