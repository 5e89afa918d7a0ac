"""The rattle heard: each gear mesh's contact force filtered by a structure-borne transfer to the
sound pressure at a listening point, written as WAV files and measured with psychoacoustic
metrics (docs/SOUND.md; the `gearrattle-study listen` command and the studies' --sound).

meshes: the mesh forces of an FMU, sampled finely through fmpy; modal and impulse: the two
kinds of transfer; render: forces to pressure; metrics: the WAVs' calibration, loudness,
sharpness and A-weighted level; listen: the command; study: a study point's sound columns;
demo: the sound part of make demo."""
