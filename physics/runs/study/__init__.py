"""``rotordrop study``: published drop studies re-run as ensembles (Markdown + PNG + JSON).

``rotordrop study paper [--quick] [--jobs N] [--scene S] [--set K=V] --out DIR`` runs the three
studies of Kärkkäinen, Sopanen & Mikkola §V (friction, support stiffness, support damping), the
claims table and the sensitivity to every assumed parameter. ``rotordrop study sweep --vary
KEY=VALUES [--vary KEY=VALUES] [--members N]`` is a parameter study of the passive drop over one
to three scene keys (:mod:`physics.runs.study.parametric`). Both run on ``--backend local|ray``
(:mod:`physics.runs.backend`) and keep every finished drop in ``--out`` for ``--resume``. Registration is light: the heavy
modules are imported by the handler.
"""
