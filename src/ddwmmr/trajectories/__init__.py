"""Desired end-effector trajectories: parametric, sampled, scaled, and file loading."""

from ddwmmr.trajectories.base import Trajectory, trajectory_name
from ddwmmr.trajectories.files import available_trajectories, load_trajectory
from ddwmmr.trajectories.parametric import Ellipse, Rectangle
from ddwmmr.trajectories.sampled import SampledTrajectory, read_csv
from ddwmmr.trajectories.scaled import ScaledTrajectory

__all__ = [
    "Ellipse",
    "Rectangle",
    "SampledTrajectory",
    "ScaledTrajectory",
    "Trajectory",
    "available_trajectories",
    "load_trajectory",
    "read_csv",
    "trajectory_name",
]
