"""Nonlinear model predictive control with CasADi: models, OCP, solvers, minimum time.

* :mod:`ddwmmr.mpc.models`: the prediction models (kinematic, thesis plant's forces);
* :mod:`ddwmmr.mpc.ocp`: the multiple-shooting OCP (tracking and free-horizon reach);
* :mod:`ddwmmr.mpc.solvers`: real-time iteration / Gauss-Newton SQP on HPIPM, and nlpsol;
* :mod:`ddwmmr.mpc.terminal`: the LQR terminal cost (python-control);
* :mod:`ddwmmr.mpc.options`: its options, one frozen object resolved for the plant;
* :mod:`ddwmmr.mpc.controller`: the controller behind method ``mpc``, with
  :mod:`ddwmmr.mpc.problem` (one OCP with its solvers), :mod:`ddwmmr.mpc.cache` (the OCPs
  shared between controllers), :mod:`ddwmmr.mpc.stall` (when a waypoint plan restarts
  cold) and :mod:`ddwmmr.mpc.braking` (the braking step);
* :mod:`ddwmmr.mpc.min_time`: the minimum time of a scenario (the physical limit).
"""
