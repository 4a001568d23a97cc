"""Flexible rotor foundation: Timoshenko shaft elements, assembly, modal reduction, ROSS import.

Standalone physics (numpy only); the drop kernel (physics/model.py) does not use it yet. See
docs/flexible.md.
"""
