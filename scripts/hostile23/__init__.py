"""Issue 23's hostile campaign (scripts/hostile_23.py): one module per surface attacked, and
common.py for running the programs, judging their runs and reading their files."""
