"""The physical limit of the thesis scenarios, bracketed (docs/mpc.md, "The physical
limit, bracketed").

* :mod:`ddwmmr.bounds.search`: the best-known minimum time, a systematic multistart of
  the minimum-time OCP (:mod:`ddwmmr.mpc.min_time`) certified by an open-loop replay on
  the thesis plant (:mod:`ddwmmr.bounds.replay`); starts in :mod:`ddwmmr.bounds.starts`;
* :mod:`ddwmmr.bounds.lower`: a true lower bound, a relaxation solved to global
  optimality;
* :mod:`ddwmmr.bounds.accounting`: where a trajectory's time goes against that bound
  (the force budget's terms, summed over the thesis plant's exact steps);
* :mod:`ddwmmr.bounds.diffdrive`: the check of the OCP where the answer is known
  (Balkcom and Mason's bounded-velocity differential drive);
* :mod:`ddwmmr.bounds.batch`: both for a batch of scenarios, cached per scenario (the
  ``python -m ddwmmr.bounds`` tool, :mod:`ddwmmr.cli.bounds`).
"""
