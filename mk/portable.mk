# Portable binaries, built with zig through cargo-zigbuild:
#   linux64   binaries/linux64/MODEL.so for glibc 2.17 (RHEL 7 and every later Linux),
#   darwin64  binaries/darwin64/MODEL.dylib, universal (x86_64 + arm64), macOS 11 or later,
# for each FMU of MODELS (the Makefile), and every binary of an FMU stripped when packaged: the unstripped copies, with their line
# tables, stay in target/fmu/debug/<platform>/ for debugging. tests/portable/check.sh checks
# the packaged binaries (`make test-portable`, part of `make test`).
# Installs what it needs when missing: zig and cargo-zigbuild (PyPI's prebuilt ziglang and
# cargo-zigbuild wheels, pinned in requirements.txt, into the .venv), the rustup targets, and
# Debian's llvm (llvm-strip, llvm-objdump, llvm-nm, llvm-lipo) with apt-get when root.

LINUX_TARGET := x86_64-unknown-linux-gnu.2.17
DARWIN_ARCHS := x86_64 aarch64
# $(call linux_so,CRATE), $(call darwin_slices,CRATE): the binaries cargo builds.
linux_so = target/x86_64-unknown-linux-gnu/release/lib$(1).so
darwin_slices = $(foreach a,$(DARWIN_ARCHS),target/$(a)-apple-darwin/release/lib$(1).dylib)

FMU_PLATFORMS += linux64:so darwin64:dylib
TEST_TARGETS += test-portable

.PHONY: zig-toolchain llvm-tools test-portable

# The FMUs' crates (fmus/) are cdylibs alone: with an rlib crate type beside, LTO keeps every
# Rust function public and the linkers keep much of them (win64 four times larger:
# docs/DECISIONS.md D23). One cargo call builds all of them for the three zig platforms, so
# that their whole-program LTO links, single-threaded each, run side by side.
# cargo-zigbuild runs from target/: zig prints its include directories relative to the working
# directory when they lie below it (the .venv does), and cargo-zigbuild hands them as they are to
# bindgen (fmi-sys), which runs elsewhere and then finds no stddef.h. cargo still reads
# .cargo/config.toml from the parent directory. MACOSX_DEPLOYMENT_TARGET sets the dylib's
# minimum macOS (zig's default is its newest).
ZIGBUILD = mkdir -p target && cd target && \
	CARGO_ZIGBUILD_PYTHON_PATH=$(CURDIR)/$(PY) MACOSX_DEPLOYMENT_TARGET=11.0 \
	$(CURDIR)/$(VENV)/bin/cargo-zigbuild build --manifest-path $(CURDIR)/Cargo.toml --release --lib

# zig's Mach-O linker ignores rustc's exported-symbols list: mk/darwin-link.py, set as the
# linker here, keeps the exports to fmi2* and fmi3* (cargo's --config wins over
# cargo-zigbuild's setting). cargo decides what to rebuild; the rule always asks it.
ZIG_LIBS := $(foreach c,$(CRATES),$(call linux_so,$(c)) $(call darwin_slices,$(c)))
$(ZIG_LIBS) &: FORCE | libclang zig-toolchain
	$(ZIGBUILD) $(addprefix -p ,$(CRATES)) --target $(LINUX_TARGET) \
		$(foreach a,$(DARWIN_ARCHS),--target $(a)-apple-darwin --config 'target.$(a)-apple-darwin.linker="$(CURDIR)/mk/darwin-link.py"')

# The unstripped copy of each binary of model $(1), crate $(2), that goes into the FMU (the two
# darwin slices joined into one universal dylib), then the stripped one (below).
define portable_rules
$(FMU_DEBUG)/linux64/$(1).so: $(call linux_so,$(2))

$(FMU_DEBUG)/darwin64/$(1).dylib: $(call darwin_slices,$(2)) | llvm-tools
	@mkdir -p $$(@D)
	$$(LLVM_BIN)/llvm-lipo -create -output $$@ $$^
endef
$(foreach m,$(MODELS),$(eval $(call portable_rules,$(m),$(crate_$(m)))))

# llvm-strip also re-signs the arm64 slice (ad hoc, as the linker did): macOS on Apple
# silicon loads no code whose signature does not match.
$(FMU_DEBUG)/%:
	@mkdir -p $(@D)
	cp $^ $@

$(FMU_STRIPPED)/%: $(FMU_DEBUG)/% | llvm-tools
	@mkdir -p $(@D)
	llvm-strip --strip-all -o $@ $<

# zig exports the two names of the Mach-O header from every dylib: mk/darwin-exports.py takes
# them out of the export trie, then llvm-strip lays the dylib out again and re-signs it.
$(FMU_STRIPPED)/darwin64/%.dylib: $(FMU_DEBUG)/darwin64/%.dylib mk/darwin-exports.py | llvm-tools
	@mkdir -p $(@D)
	python3 mk/darwin-exports.py $< $@.fmi2
	llvm-strip --strip-all -o $@ $@.fmi2
	rm $@.fmi2

## test-portable: the FMUs' binaries: glibc 2.17, exports, linked libraries, no debug info, size
test-portable: fmu | llvm-tools
	$(foreach m,$(MODELS),tests/portable/check.sh target/fmu/$(m).fmu &&) true

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
