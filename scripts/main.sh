#!/usr/bin/env bash
# The main job: set up, build, run the glare-brightness 2AFC protocol with the
# model observer, headless, through the real rendering pipeline into
# out/study.db, then analyse it (psychometric fits with bootstrap intervals,
# brightness enhancement by glare, figures) into out/report/report.html.
# (The example scenes render with scripts/render-examples.sh.)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
atonlab="${ATONLAB_BUILD_DIR:-build}/runner/atonlab"
mkdir -p out
rm -f out/study.db out/study.db-wal out/study.db-shm
rm -rf out/report
"$atonlab" run protocols/examples/glare_brightness_2afc.toml --db out/study.db --model-observer --headless
echo
"$atonlab" analyze out/study.db --out out/report
echo "The study file is $(pwd)/out/study.db (schema: docs/store.md)."
echo "Open the report: $(pwd)/out/report/report.html (docs/analysis.md)."
