"""Benchmarking: episodes of a controller or policy (:mod:`~agents.benchmarking.rollout`), their
score (:mod:`~agents.benchmarking.score`), ``rotordrop evaluate | benchmark | ride-through |
tune`` (:mod:`~agents.benchmarking.evaluate`, :mod:`~agents.benchmarking.benchmark`,
:mod:`~agents.benchmarking.ride_through`, :mod:`~agents.benchmarking.tune`), the robust suite
(:mod:`~agents.benchmarking.robust`), the cross-entropy search (:mod:`~agents.benchmarking.search`,
on Ray Tune: :mod:`~agents.benchmarking.ray_search`), the figures and the results page."""
