#!/usr/bin/env bash
# unit.python.install: `cmake --install BUILD --prefix P --component python`
# puts the package into P/lib/python3.X/site-packages/atonlab (docs/python.md
# "Getting it"), and Python imports it from there with nothing of the build
# tree on its path: the module, its stub and py.typed.
# Usage: install.sh BUILD_DIR WORK_DIR PYTHON
set -euo pipefail
build=$1 work=$2 python=$3
rm -rf "$work" && mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" --component python > "$work/install.log"
site=$(echo "$work"/prefix/lib/python3.*/site-packages)
for f in __init__.py __init__.pyi py.typed; do
  test -f "$site/atonlab/$f" || { echo "not installed: $site/atonlab/$f" >&2; exit 1; }
done
cd "$work"
PYTHONPATH="$site" "$python" -c "
import atonlab, numpy as np
assert atonlab.__file__.startswith('$site'), atonlab.__file__
assert abs(atonlab.light.intensity_cd(atonlab.light.range_nmi(250.0)) - 250.0) < 1e-9
assert atonlab.tonemap(np.full((2, 2, 3), 0.03, np.float32)).dtype == np.uint8
print('installed and imported from', atonlab.__file__)
"
