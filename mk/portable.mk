# Portable binaries, built with zig through cargo-zigbuild:
#   linux64   binaries/linux64/GearRattle.so for glibc 2.17 (RHEL 7 and every later Linux),
#   darwin64  binaries/darwin64/GearRattle.dylib, universal (x86_64 + arm64), macOS 11 or later,
# and every binary of the FMU stripped when packaged: the unstripped copies, with their line
# tables, stay in target/fmu/debug/<platform>/ for debugging. tests/portable/check.sh checks
# the packaged binaries (`make test-portable`, part of `make test`).
# Installs what it needs when missing: zig and cargo-zigbuild (PyPI's prebuilt ziglang and
# cargo-zigbuild wheels, pinned in requirements.txt, into the .venv), the rustup targets, and
# Debian's llvm (llvm-strip, llvm-objdump, llvm-nm, llvm-lipo) with apt-get when root.

LINUX_TARGET := x86_64-unknown-linux-gnu.2.17
LINUX_SO := target/x86_64-unknown-linux-gnu/release/libgear_rattle.so
DARWIN_ARCHS := x86_64 aarch64
DARWIN_SLICES := $(foreach a,$(DARWIN_ARCHS),target/$(a)-apple-darwin/release/libgear_rattle.dylib)

FMU_DEPS += $(FMU_STRIPPED)/linux64/GearRattle.so $(FMU_STRIPPED)/darwin64/GearRattle.dylib
PACKAGE_FLAGS += --lib $(FMU_STRIPPED)/linux64/GearRattle.so \
	--darwin64 $(FMU_STRIPPED)/darwin64/GearRattle.dylib
TEST_TARGETS += test-portable

.PHONY: zig-toolchain llvm-tools test-portable

# Each binary is built as a cdylib alone (`cargo rustc --crate-type cdylib`): with the rlib
# crate type of Cargo.toml beside it, LTO keeps every Rust function public and the linkers
# keep much of them (win64 four times larger: docs/DECISIONS.md D23).
# cargo-zigbuild runs from target/: zig prints its include directories relative to the working
# directory when they lie below it (the .venv does), and cargo-zigbuild hands them as they are to
# bindgen (fmi-sys), which runs elsewhere and then finds no stddef.h. cargo still reads
# .cargo/config.toml from the parent directory. MACOSX_DEPLOYMENT_TARGET sets the dylib's
# minimum macOS (zig's default is its newest).
ZIGBUILD = mkdir -p target && cd target && \
	CARGO_ZIGBUILD_PYTHON_PATH=$(CURDIR)/$(PY) MACOSX_DEPLOYMENT_TARGET=11.0 \
	$(CURDIR)/$(VENV)/bin/cargo-zigbuild rustc --manifest-path $(CURDIR)/Cargo.toml --release --lib --crate-type cdylib

# cargo decides what to rebuild; these rules always ask it.
$(LINUX_SO): FORCE | libclang zig-toolchain
	$(ZIGBUILD) --target $(LINUX_TARGET)

# zig's Mach-O linker ignores rustc's exported-symbols list: mk/darwin-link.py, set as the
# linker here, keeps the exports to fmi2* (cargo's --config wins over cargo-zigbuild's setting).
target/%-apple-darwin/release/libgear_rattle.dylib: FORCE | libclang zig-toolchain
	$(ZIGBUILD) --target $*-apple-darwin --config 'target.$*-apple-darwin.linker="$(CURDIR)/mk/darwin-link.py"'

# The unstripped copy of each binary that goes into the FMU (the two darwin slices joined into
# one universal dylib), then the stripped one. llvm-strip also re-signs the arm64 slice (ad hoc,
# as the linker did): macOS on Apple silicon loads no code whose signature does not match.
$(FMU_DEBUG)/linux64/GearRattle.so: $(LINUX_SO)
$(FMU_DEBUG)/%:
	@mkdir -p $(@D)
	cp $^ $@

$(FMU_DEBUG)/darwin64/GearRattle.dylib: $(DARWIN_SLICES) | llvm-tools
	@mkdir -p $(@D)
	$(LLVM_BIN)/llvm-lipo -create -output $@ $^

$(FMU_STRIPPED)/%: $(FMU_DEBUG)/% | llvm-tools
	@mkdir -p $(@D)
	llvm-strip --strip-all -o $@ $<

# zig exports the two names of the Mach-O header from every dylib: mk/darwin-exports.py takes
# them out of the export trie, then llvm-strip lays the dylib out again and re-signs it.
$(FMU_STRIPPED)/darwin64/GearRattle.dylib: $(FMU_DEBUG)/darwin64/GearRattle.dylib mk/darwin-exports.py | llvm-tools
	@mkdir -p $(@D)
	python3 mk/darwin-exports.py $< $@.fmi2
	llvm-strip --strip-all -o $@ $@.fmi2
	rm $@.fmi2

## test-portable: the FMU's binaries: glibc 2.17, exports, linked libraries, no debug info, size
test-portable: fmu | llvm-tools
	tests/portable/check.sh $(FMU)

zig-toolchain: $(VENV)/.installed
	@for a in $(DARWIN_ARCHS); do \
		rustup target list --installed | grep -qx $$a-apple-darwin || { \
			echo "Rust target $$a-apple-darwin missing: rustup target add $$a-apple-darwin"; \
			rustup target add $$a-apple-darwin; }; \
	done

# Debian's llvm puts llvm-strip, llvm-objdump and llvm-nm on the PATH, llvm-lipo only in its
# versioned directory. Evaluated when a recipe runs, after llvm-tools.
LLVM_BIN = $(patsubst %/,%,$(lastword $(sort $(dir $(wildcard /usr/lib/llvm-*/bin/llvm-lipo)))))
llvm-tools:
	$(call apt_install,llvm,command -v llvm-strip >/dev/null && command -v llvm-objdump >/dev/null && command -v llvm-nm >/dev/null && compgen -G '/usr/lib/llvm-*/bin/llvm-lipo' >/dev/null)
