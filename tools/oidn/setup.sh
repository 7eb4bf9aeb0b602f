#!/usr/bin/env bash
# Installs Open Image Denoise for the `oidn` feature of rt-denoise and for the pyoidn peer
# measurement (tools/oidn/pyoidn_denoise.py), and prints the library path to export as OIDN_LIB.
#
# The pyoidn wheel from PyPI carries libOpenImageDenoise.so.2 with its core, its CPU device
# module (network weights built in) and libtbb in site-packages/pyoidn/oidn/lib (found through
# RPATH $ORIGIN/../lib, so nothing else is needed). Idempotent: installs only what is missing.
#
#   export OIDN_LIB="$(tools/oidn/setup.sh)"
#   cargo test --release -p rt-denoise --features oidn
set -euo pipefail
PY="${PYTHON:-python3}"
if ! "$PY" -c 'import pyoidn, OpenEXR, numpy' 2>/dev/null; then
    "$PY" -m pip install --quiet 'pyoidn>=2.3,<3' 'openexr>=3.3' numpy >&2
fi
lib="$("$PY" -c 'import os, pyoidn; print(os.path.join(os.path.dirname(pyoidn.__file__), "oidn", "lib", "libOpenImageDenoise.so.2"))')"
if [ ! -e "$lib" ]; then
    echo "setup.sh: pyoidn is installed but $lib is missing" >&2
    exit 1
fi
echo "$lib"
