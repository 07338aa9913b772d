"""A plant plug-in in one file: the kinematic model by Euler steps, without limits."""

import math

import numpy as np

from ddwmmr.plants import Observation, register_plant


@register_plant("ideal", interfaces=("velocity",))
class IdealPlant:
    """Kinematic model by Euler steps, no wheel, joint or angle limits."""

    extra_columns = ()

    def __init__(self, robot):
        self.robot, self.q, self.u = robot, [0.0] * 5, (0.0, 0.0, 0.0, 0.0)

    def reset(self, q0, dt):
        self.q, self.u = [float(a) for a in q0], (0.0, 0.0, 0.0, 0.0)

    def observe(self):
        return Observation(tuple(self.q), self.u[0], self.u[1])

    def limit(self, q, u):
        return np.asarray(u, dtype=float), False  # no actuator limits

    def step(self, t, command, dt, policy=None):
        x, y, phi, th1, th2 = self.q
        v, w, r1, r2 = self.u = tuple(float(a) for a in command)
        self.q = [x + dt * v * math.cos(phi), y + dt * v * math.sin(phi)]
        self.q += [phi + dt * w, th1 + dt * r1, th2 + dt * r2]

    def extra_values(self):
        return ()

    def summarize(self, timeseries):
        return {}
