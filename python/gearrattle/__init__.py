"""GearRattle's Python package: the study runner (gearrattle.study, the `gearrattle-study`
command) and the helpers that the tests and scripts share: the independent reference solution
(gearrattle.reference), the rattle statistics of sampled outputs (gearrattle.rattle_stats)
and the co-simulation drivers (gearrattle.masters, gearrattle.monolithic)."""
