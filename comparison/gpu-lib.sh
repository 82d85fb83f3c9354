# Shared by the comparison/gpu-*.sh investigation scripts (sourced, not run).
# The caller sets bin (release binaries), out (the results folder), log (the
# JSONL file) and errors (where the apps' stderr goes).

# run LABEL APP OPTIONS...: one headless run of twinray-APP; appends a line
# naming the label and the command, then the app's --json report, or a
# `failed` line.
run() {
    local label=$1 app=$2
    shift 2
    echo "{\"label\":\"$label\",\"cmd\":\"twinray-$app $*\"}" >> "$log"
    timeout 120 "$bin/twinray-$app" --headless --json "$@" >> "$log" 2>> "$errors" ||
        echo "{\"failed\":\"twinray-$app $*\"}" >> "$log"
}
