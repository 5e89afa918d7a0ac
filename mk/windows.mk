# Windows: binaries/win64/MODEL.dll in each FMU of MODELS (the Makefile), cross-built with Rust's
# x86_64-pc-windows-gnu target and MinGW-w64 (linker: mk/windows-link.sh, set in
# .cargo/config.toml), and tested under Wine against the linux64 binary (tests/windows/run.sh).
# Installs what it needs when missing: the rustup target, and with apt-get when root
# gcc-mingw-w64-x86-64 (for `make fmu`) and wine64 (for `make test-windows`).

WIN_TARGET := x86_64-pc-windows-gnu
# $(call win_dll,CRATE): the DLL cargo builds.
win_dll = target/$(WIN_TARGET)/release/$(1).dll

# Packaged stripped, the unstripped copy in target/fmu/debug/win64 (rules in mk/portable.mk).
FMU_PLATFORMS += win64:dll
TEST_TARGETS += test-windows

.PHONY: windows-toolchain windows-wine test-windows

# fmi-sys's bindgen parses the FMI headers for the Windows target against MinGW's headers,
# whose malloc.h needs clang's own include directory (mm_malloc.h) first. One cargo call builds
# every FMU's crate (cdylibs alone, like the portable binaries: see mk/portable.mk).
WIN_DLLS := $(foreach c,$(CRATES),$(call win_dll,$(c)))
$(WIN_DLLS) &: FORCE | libclang windows-toolchain
	@mm_malloc=$$(ls /usr/lib/llvm-*/lib/clang/*/include/mm_malloc.h 2>/dev/null | sort -V | tail -n 1); \
	[ -n "$$mm_malloc" ] || { echo "clang's mm_malloc.h not found (libclang-dev installs it)"; exit 1; }; \
	export BINDGEN_EXTRA_CLANG_ARGS_x86_64_pc_windows_gnu="-I$$(dirname "$$mm_malloc")"; \
	echo "BINDGEN_EXTRA_CLANG_ARGS_x86_64_pc_windows_gnu=$$BINDGEN_EXTRA_CLANG_ARGS_x86_64_pc_windows_gnu"; \
	echo "cargo build --release $(addprefix -p ,$(CRATES)) --lib --target $(WIN_TARGET)"; \
	cargo build --release $(addprefix -p ,$(CRATES)) --lib --target $(WIN_TARGET)

$(foreach m,$(MODELS),$(eval $(FMU_DEBUG)/win64/$(m).dll: $(call win_dll,$(crate_$(m)))))

## test-windows: the win64 DLLs under Wine agree with the linux64 .so; their export/import tables
test-windows: fmu | windows-toolchain windows-wine
	$(foreach m,$(MODELS),tests/windows/run.sh target/fmu/$(m).fmu &&) true

windows-toolchain:
	@rustup target list --installed | grep -qx $(WIN_TARGET) || { \
		echo "Rust target $(WIN_TARGET) missing: rustup target add $(WIN_TARGET)"; \
		rustup target add $(WIN_TARGET); }
	$(call apt_install,gcc-mingw-w64-x86-64,command -v x86_64-w64-mingw32-gcc >/dev/null)

# Debian's wine64 puts its loader in /usr/lib/wine (/usr/bin/wine comes with `wine`, which
# would also pull 32-bit parts the test does not need).
windows-wine:
	$(call apt_install,wine64,command -v wine64 >/dev/null || [ -x /usr/lib/wine/wine64 ])
