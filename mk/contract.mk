# The contracts (modelDescription/*.toml) and what is generated from them outside a build:
# docs/PARAMETERS.md (tests/contract.rs checks that it is up to date), and the generator's own
# tests (GearboxRattle's arrays, its Rust constants compiled in a crate of their own, both
# model descriptions, FMI 2.0 and FMI 3.0, through fmpy's validate_fmu).

.PHONY: docs-parameters test-generator
TEST_TARGETS += test-generator

## docs-parameters: regenerate docs/PARAMETERS.md from the contract
docs-parameters: | libclang
	cargo run --quiet --bin parameters -- docs/PARAMETERS.md

## test-generator: the contract generator's tests (fmi2-shell, feature build)
test-generator: $(VENV)/.installed | libclang
	FMPY_PYTHON=$(abspath $(PY)) $(CARGO_TEST) -p fmi2-shell --features build --lib
