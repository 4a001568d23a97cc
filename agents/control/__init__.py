"""Control: what a controller sees of the environment (:mod:`~agents.control.plant`), the
designed controllers (:mod:`~agents.control.controllers`), the residual on a baseline
(:mod:`~agents.control.residual`) and the open-loop current corrections
(:mod:`~agents.control.open_loop`)."""
