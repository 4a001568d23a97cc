"""Deprecated: the policy-file module moved to :mod:`agents.learning.policies` (``ship_policy``
to :mod:`agents.training.ship`); this folder holds the shipped policies' files. Importing it warns
until rotordrop 2.0 (docs/api/public.md)."""
import sys

from physics.moved import forward

forward(sys.modules[__name__], ("agents.learning.policies", "agents.training.ship"))
