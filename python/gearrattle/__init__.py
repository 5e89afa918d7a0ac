"""GearRattle's Python package: the study runner (gearrattle.study, the `gearrattle-study`
command) and what the tests and the scripts/ command lines share: the independent reference
solution (reference), the rattle statistics of sampled outputs (rattle_stats), the
co-simulation drivers and the monolithic drivetrain (masters, monolithic, model_exchange),
the bench scenes (scenes) and the demo over them (demo, scene_figures), the rattle map
(rattle_map), the stress cases (stress) and the reports built on them (stability, coupling).
Its modules import one way: tests/python/test_import_graph.py fails on a cycle."""
