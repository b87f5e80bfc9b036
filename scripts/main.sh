#!/usr/bin/env bash
# The main job: set up, build, and run the glare-brightness 2AFC protocol with
# the model observer, headless, through the real rendering pipeline into
# out/study.db, printing a short summary. (The example scenes render with
# scripts/render-examples.sh.)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
mkdir -p out
rm -f out/study.db out/study.db-wal out/study.db-shm
"${ATONLAB_BUILD_DIR:-build}/runner/atonlab" run protocols/examples/glare_brightness_2afc.toml \
  --db out/study.db --model-observer --headless
echo "The study file is $(pwd)/out/study.db (schema: docs/store.md)."
