#!/usr/bin/env bash
# Create .venv with Python >= 3.12 and install bcfem with its extras.
# Used by `make` (demo, test, bench), .ci/run and the Dockerfile: one install path.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${VENV:-.venv}
# `import dolfinx` first works in the venv: a finder imports dolfinx_solver (MPI first) ahead of it
mpi_first() {
  cp tools/bcfem-mpi-first.pth "$("$VENV/bin/python" -c 'import sysconfig; print(sysconfig.get_path("purelib"))')/"
}
if [ -x "$VENV/bin/python" ] && "$VENV/bin/python" -c 'import sys; sys.exit(sys.version_info < (3, 12))' \
   && [ "$VENV/.installed" -nt pyproject.toml ] && [ "$VENV/.installed" -nt tools/constraints.txt ]; then
  mpi_first
  exit 0
fi
find_python() {
  for c in "${PYTHON:-}" python3.12 python3.13 python3 python; do
    [ -n "$c" ] || continue
    command -v "$c" >/dev/null 2>&1 || continue
    if "$c" -c 'import sys; sys.exit(sys.version_info < (3, 12))' 2>/dev/null; then
      echo "$c"; return 0
    fi
  done
  return 1
}
if ! PY=$(find_python); then
  echo "bcfem needs Python >= 3.12 (the dolfinx-solver-real wheel requires it)." >&2
  echo "Install one, e.g. 'pyenv install 3.12' (.python-version pins 3.12), or set PYTHON=/path/to/python3.12." >&2
  exit 1
fi
echo "bootstrap: creating $VENV with $("$PY" --version)"
"$PY" -m venv "$VENV"
"$VENV/bin/python" -m pip install -q --upgrade pip
# pinned: map points past instabilities move with round-off (tools/constraints.txt)
"$VENV/bin/python" -m pip install -q -c tools/constraints.txt -e ".[all]"
mpi_first
touch "$VENV/.installed"
echo "bootstrap: installed bcfem into $VENV"
