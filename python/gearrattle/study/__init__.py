"""Rattle studies of the GearRattle FMU: maps, designs of experiments and tolerance Monte Carlo,
run point by point on Dask distributed (docs/STUDIES.md; the `gearrattle-study` command)."""
