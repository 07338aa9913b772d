"""Redundancy resolution: pseudoinverse, augmented task space, null-space potential."""

from ddwmmr.resolution.kernels import ats, null_space_rate, pseudoinverse

__all__ = ["ats", "null_space_rate", "pseudoinverse"]
