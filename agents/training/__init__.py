"""Training runs: ``rotordrop train`` (:mod:`~agents.training.train`, seeds side by side in
:mod:`~agents.training.seeds`), the training VecEnv (:mod:`~agents.training.training_env`), model
selection on the validation suite (:mod:`~agents.training.validation`), offline data sets and
behaviour cloning (:mod:`~agents.training.dataset`, :mod:`~agents.training.imitation`), learning
curves (:mod:`~agents.training.learning_curves`) and shipping a run as a policy of
``agents/policies/`` (:mod:`~agents.training.ship`). It sits above the benchmark, whose score
selects the models."""
