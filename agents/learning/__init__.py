"""What a learned policy is made of: its algorithm and hyperparameters
(:mod:`~agents.learning.hyperparams`, :mod:`~agents.learning.config_checks`), its reward
(:mod:`~agents.learning.reward`) and exploration (:mod:`~agents.learning.exploration`), and its
files: the loader of trained and shipped policies (:mod:`~agents.learning.policies`) and the
self-contained zips (:mod:`~agents.sb3_policy`). The benchmark runs these policies; the
training runs that make them sit above it (:mod:`agents.training`)."""
