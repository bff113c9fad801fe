"""Tasks for learning, in the Gymnasium convention (no Gymnasium needed; docs/python.md).

    task = phyxel.tasks.Resection()
    observation, info = task.reset()
    observation, reward, terminated, truncated, info = task.step([0.02, 0.0, 0.0])
"""

import numpy as np

from ._core import Simulation, SimulationError


def resection_scene():
    """The default scene of Resection: a block of tissue, fixed at its base, with a stiffer
    tumour inside and a scalpel above it (its edge along +x, its shaft along +z)."""
    return {
        "simulation": {"dt": 2.4e-4, "steps": 1, "gravity": [0, 0, -9.81]},
        "objects": [
            {
                "name": "tissue",
                "shape": {"type": "box", "min": [-0.02, -0.015, 0.0], "max": [0.02, 0.015, 0.02]},
                "spacing": 0.003,
                "material": {"young": 5000, "poisson": 0.45, "density": 1040, "damping": 20},
                "inclusions": [
                    {
                        "name": "tumour",
                        "shape": {"type": "sphere", "center": [0.0, 0.0, 0.012], "radius": 0.005},
                        "material": {"young": 20000, "poisson": 0.45, "density": 1050},
                    }
                ],
                "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.0015]}],
            }
        ],
        "tools": [
            {
                "name": "scalpel",
                "type": "scalpel",
                "shape": {"type": "capsule", "radius": 0.0004, "length": 0.04},
                "blade": {"length": 0.02, "edge": [1, 0, 0]},
                "cut_force_threshold": 0.02,
                "path": [{"t": 0.0, "position": [-0.009, 0.0, 0.021], "axis": [0, 0, 1]}],
                "friction": 0.2,
            }
        ],
        "output": {"every": 0},
    }


class Resection:
    """Cut a tumour free of the tissue around it with a scalpel.

    action       (3,) the scalpel's velocity, m/s; its norm is clipped to max_speed. The tool
                 moves there over the next steps_per_action simulation steps.
    observation  (10,) float64: the scalpel's tip position (m, 3), its axis (3), the force on it
                 over the last step (N, 3) and the tumour's exposure (1).
    reward       the exposure gained by the action minus force_weight x |force| (N).
    terminated   the tumour is cut free all round (exposure >= 1), or the simulation failed
                 (info["failed"] holds the message).
    truncated    max_actions actions were taken.

    The exposure is the fraction of the pairs joining the tumour's phyxels to the tissue around
    it that are cut (Simulation.exposure).
    """

    observation_shape = (10,)
    action_shape = (3,)

    def __init__(self, scene=None, tool="scalpel", tumour="tumour", device="cpu", threads=0,
                 steps_per_action=10, max_actions=200, max_speed=0.1, force_weight=0.01):
        self.scene = scene if scene is not None else resection_scene()
        self.tool = tool
        self.tumour = tumour
        self.device = device
        self.threads = threads
        self.steps_per_action = int(steps_per_action)
        self.max_actions = int(max_actions)
        self.max_speed = float(max_speed)
        self.force_weight = float(force_weight)
        self.action_high = np.full(3, self.max_speed)
        self.action_low = -self.action_high
        self.sim = None
        self._actions = 0
        self._exposure = 0.0

    def reset(self, seed=None, options=None):
        """A fresh simulation of the scene. Returns (observation, info). The task is
        deterministic: seed and options are accepted for the convention and not used."""
        del seed, options
        self.sim = Simulation(self.scene, device=self.device, threads=self.threads)
        self._actions = 0
        self._exposure = self.sim.exposure(self.tumour)
        return self._observation(), {"time": self.sim.time}

    def step(self, action):
        """Moves the scalpel at velocity `action` for steps_per_action steps. Returns
        (observation, reward, terminated, truncated, info)."""
        if self.sim is None:
            raise RuntimeError("Resection.step: call reset() first")
        v = np.asarray(action, dtype=np.float64).reshape(3)
        speed = np.linalg.norm(v)
        if not np.isfinite(speed):
            raise ValueError("Resection.step: the action must be finite")
        if speed > self.max_speed:
            v = v * (self.max_speed / speed)
        position, axis = self.sim.tool_pose(self.tool)
        duration = self.steps_per_action * self.sim.dt
        self.sim.set_tool_pose(self.tool, position + v * duration, axis)
        info = {}
        try:
            self.sim.advance(self.steps_per_action)
            failed = False
        except SimulationError as e:
            failed = True
            info["failed"] = str(e)
        self._actions += 1
        observation = self._observation(failed)
        exposure = float(observation[9])
        reward = exposure - self._exposure
        reward -= self.force_weight * float(np.linalg.norm(observation[6:9]))
        self._exposure = exposure
        terminated = failed or exposure >= 1.0
        truncated = not terminated and self._actions >= self.max_actions
        info["time"] = self.sim.time
        info["exposure"] = exposure
        return observation, reward, terminated, truncated, info

    def _observation(self, failed=False):
        position, axis = self.sim.tool_pose(self.tool)
        force = np.zeros(3) if failed else self.sim.tool_force(self.tool)
        exposure = self._exposure if failed else self.sim.exposure(self.tumour)
        return np.concatenate([position, axis, force, [exposure]]).astype(np.float64)
