"""Controllers, SB3 training, evaluation and benchmark for the rotor-drop environments
(docs/agents.md). Heavy dependencies (SB3, torch) are imported where they are used."""
