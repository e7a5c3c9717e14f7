# Shared set-up for scripts/run and scripts/test (sourced, not executed).
# Creates .venv, installs the Python dependencies and builds the wheel in place (maturin develop).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
# Cargo's target directory lives outside the clone so rebuilds stay incremental across clones.
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-${PARITYSIM_CACHE_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/paritysim}/target}"
export PIP_DISABLE_PIP_VERSION_CHECK=1
PYTHON="${PYTHON:-python3}"
if [ ! -x .venv/bin/python ]; then
    "$PYTHON" -m venv .venv
fi
# shellcheck disable=SC1091
. .venv/bin/activate
paritysim_install() {  # $1: pip extras, e.g. "test"
    local extras="${1:-}"
    python -m pip install -q "maturin>=1.7,<2"
    # Runtime (and test) dependencies from pyproject.toml, then the extension in release mode.
    python - "$extras" <<'PY' > .venv/requirements.txt
import sys, tomllib
meta = tomllib.load(open("pyproject.toml", "rb"))["project"]
deps = list(meta["dependencies"])
for extra in filter(None, sys.argv[1].split(",")):
    deps += meta["optional-dependencies"][extra]
print("\n".join(deps))
PY
    python -m pip install -q -r .venv/requirements.txt
    maturin develop --release --quiet 2>&1 | grep -vE '^\s*(Compiling|Finished|Building|Installed|📦|🔗|🐍|✏️|🛠)' || true
    python -c "import paritysim" || { echo "paritysim failed to import after the build" >&2; exit 1; }
}
