"""Import before wl-based scripts: wl.Gym builds its SafetyGate with pairs="all" (the bench gate suite's gated_ratio rows)."""
import wl as _wl
from wl import *  # noqa
class GymAll(_wl.Gym):
    def __init__(self, work, horizon, brake):
        import gymnasium as gym
        import monitor.envs  # noqa: F401
        from monitor.gym_gate import SafetyGate
        self.env = SafetyGate(gym.make(work), pairs="all", brake=brake, brake_horizon=horizon)
        self.bare = gym.make(work)
        self.gate = self.env.gate
        self.model, self.data = self.env.unwrapped.model, self.env.unwrapped.data
_wl.Gym = GymAll
