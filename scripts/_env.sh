# Shared set-up for scripts/run, scripts/test and scripts/docs (sourced, not executed).
# Creates .venv, installs the Python dependencies and builds the extension in place (maturin develop).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
# Cargo's target directory lives outside the clone so rebuilds stay incremental across clones.
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-${PARITYSIM_CACHE_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/paritysim}/target}"
export PIP_DISABLE_PIP_VERSION_CHECK=1
PYTHON="${PYTHON:-python3}"
# The cargo profile of the extension: `release` for use; scripts/test picks `ci`, the profile its
# cargo tests build with, so the engine compiles once for both (Cargo.toml, docs/findings.md §33).
export PARITYSIM_PROFILE="${PARITYSIM_PROFILE:-release}"

# stage NAME COMMAND...: runs COMMAND between "== NAME" and "== NAME: 12 s" (its output shown).
stage() {
    local name="$1" start=$SECONDS
    shift
    echo "== $name"
    "$@"
    echo "== $name: $((SECONDS - start)) s"
}

if [ ! -x .venv/bin/python ]; then
    stage "create .venv" "$PYTHON" -m venv .venv
fi
# shellcheck disable=SC1091
. .venv/bin/activate

# What pip prints for requirements it skips or already has (maturin runs pip without -q).
PIP_NOISE='^(Ignoring [^ ]+: markers |Requirement already satisfied|Looking in links|Obtaining |Checking if build backend)'

# uv installs the dependencies when it can be had (35 s with pip against 6 s with uv for the test
# extras here; docs/findings.md §33); pip otherwise.
_pip() {
    if [ -x .venv/bin/uv ]; then .venv/bin/uv pip "$@"; else python -m pip "$@"; fi
}

_python_deps() {  # $1: pip extras, e.g. "test,docs"
    python -m pip install -q "maturin>=1.7,<2"
    python -m pip install -q uv >/dev/null 2>&1 || echo "(uv unavailable: installing with pip)"
    # Runtime (and extra) dependencies from pyproject.toml: only the lines needed, no markers.
    python - "$1" <<'PY' > .venv/requirements.txt
import sys, tomllib
meta = tomllib.load(open("pyproject.toml", "rb"))["project"]
deps = list(meta["dependencies"])
for extra in filter(None, sys.argv[1].split(",")):
    deps += meta["optional-dependencies"][extra]
print("\n".join(deps))
PY
    _pip install -q -r .venv/requirements.txt
}

_build_extension() {
    # Once the package is installed (editable), only the extension is rebuilt in place; the first
    # time maturin also installs it. Cargo's "Compiling ..." lines show the progress.
    local install=(--skip-install)
    python -c "import importlib.metadata as m; m.version('paritysim')" 2>/dev/null || install=()
    if [ ${#install[@]} -eq 0 ] && [ -x .venv/bin/uv ]; then install=(--uv); fi
    maturin develop --profile "$PARITYSIM_PROFILE" "${install[@]}" 2>&1 | { grep --line-buffered -vE "$PIP_NOISE" || true; }
    python -c "import paritysim" || { echo "paritysim failed to import after the build" >&2; exit 1; }
}

paritysim_install() {  # $1: pip extras, e.g. "test"
    stage "python dependencies (${1:-runtime})" _python_deps "${1:-}"
    stage "build the extension (maturin develop --profile $PARITYSIM_PROFILE; cold: ~2 min on 2 cores)" _build_extension
}
