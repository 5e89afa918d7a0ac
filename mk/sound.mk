# The rattle as sound (docs/SOUND.md): the package python/gearrattle/sound (`gearrattle-study
# listen`, --sound on the studies), its tests (tests/sound, run by pytest with the others:
# pytest.ini), its benchmark and the A/B example of the docs. `make demo` writes the sound of S1
# and of the default gearbox warm and cold.
#   make bench-sound      CPU of the WAV and of the metrics against the simulation alone, and the
#                         pressure's error against the force's sampling (S1, 1 s), then the WAV of
#                         10 s of the default gearbox against its simulation alone (printed)
#   make sound-example    the A/B example of docs/SOUND.md (S1 against S3) -> docs/sound/

SOUND_EXAMPLE := target/sound/ab_S1_S3

.PHONY: bench-sound sound-example

## bench-sound: the sound's cost against the simulation alone, and its error against the force's sampling
bench-sound: fmu $(VENV)/.installed
	$(BENCH_PY) scripts/bench_sound.py --fmu $(FMU) --duration 1
	$(BENCH_PY) scripts/bench_sound.py --fmu $(GEARBOX_FMU) --duration 10 --cost

## sound-example: the A/B example of docs/SOUND.md (S1 against S3) -> docs/sound/
sound-example: fmu $(VENV)/.installed
	$(VENV)/bin/gearrattle-study listen --fmu $(FMU) --duration 1 --compare --b-set A_rms=500 \
		--out $(SOUND_EXAMPLE) --quiet
	@mkdir -p docs/sound
	cp $(SOUND_EXAMPLE)/sound.txt docs/sound/ab_S1_S3.txt
	cp $(SOUND_EXAMPLE)/loudness.png docs/sound/ab_S1_S3_loudness.png
	cp $(SOUND_EXAMPLE)/A/spectrogram.png docs/sound/S1_spectrogram.png
