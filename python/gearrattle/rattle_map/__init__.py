"""The rattle map of the paper's sweep and the model's no-impact threshold (`make rattle-map`):
sweep runs it (sweep.run), grid holds the per-point statistics and the CSV files, figures and
summary what is drawn and printed."""
