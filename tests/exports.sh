# The functions each FMU's binaries export, for tests/portable/check.sh and
# tests/windows/run.sh (sourced): FMI 2.0's (tests/fmi2_functions.txt) for every model, and
# FMI 3.0's (tests/fmi3_functions.txt) for the models whose library fmi3-shell exports too.
FMI3_MODELS="GearRattle GearboxRattle"

# $1: the model; prints the functions, sorted, one a line.
expected_exports() {
    local lists=("$ROOT/tests/fmi2_functions.txt")
    [[ " $FMI3_MODELS " == *" $1 "* ]] && lists+=("$ROOT/tests/fmi3_functions.txt")
    cat "${lists[@]}" | grep -v '^#' | tr -s ' \n' '\n\n' | sed '/^$/d' | sort
}

# $1: the model; names what it exports, for the messages.
export_prefixes() {
    if [[ " $FMI3_MODELS " == *" $1 "* ]]; then echo "fmi2*, fmi3* and gearRattleDoStepSampled"; else echo "fmi2* and gearRattleDoStepSampled"; fi
}
