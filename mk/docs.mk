# docs/PARAMETERS.md: the parameter and input tables generated from the contract
# (modelDescription/GearRattle.toml); tests/contract.rs checks that it is up to date.

.PHONY: docs-parameters

## docs-parameters: regenerate docs/PARAMETERS.md from the contract
docs-parameters: | libclang
	cargo run --quiet --bin parameters -- docs/PARAMETERS.md
