"""Batch work over the qsgi executable (issue 10): speed/accuracy sweeps (grid points rendered,
judged with `qsgi compare`, tabulated in sweep.csv and plotted; scripts/sweep.py) and Slurm job
arrays of sweep points and of frame chunks (scripts/slurm/render.py)."""
