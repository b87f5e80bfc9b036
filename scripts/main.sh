#!/usr/bin/env bash
# The main job: set up, build, and render the example scenes to out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/render-examples.sh
