#!/usr/bin/env bash
# The main job: set up, build, run the glare-brightness designs with the
# model observer, headless, through the real rendering pipeline — the
# two-interval 2AFC (glare_brightness_2afc.toml) into out/study.db and the
# side-by-side glare-vs-no-glare 2AFC (glare_side_by_side.toml: both lights in
# one frame, each with its own glare model) into out/side_by_side.db — then
# analyse each (psychometric fits with bootstrap intervals, brightness
# enhancement by glare, figures) into out/report/report.html and
# out/report-side-by-side/report.html. (Two study files: the enhancement
# figure draws one line per tone mapper, which the two designs would share.)
# (The example scenes render with scripts/render-examples.sh.)
set -euo pipefail
cd "$(dirname "$0")/.."
# Only the program: scripts/test.sh builds the rest into the same build/.
ATONLAB_BUILD_TARGETS="${ATONLAB_BUILD_TARGETS:-atonlab}" bash scripts/setup.sh
atonlab="${ATONLAB_BUILD_DIR:-build}/runner/atonlab"
mkdir -p out
rm -f out/study.db out/study.db-wal out/study.db-shm out/side_by_side.db out/side_by_side.db-wal out/side_by_side.db-shm
rm -rf out/report out/report-side-by-side
"$atonlab" run protocols/examples/glare_brightness_2afc.toml --db out/study.db --model-observer --headless
echo
"$atonlab" run protocols/examples/glare_side_by_side.toml --db out/side_by_side.db --model-observer --headless
echo
"$atonlab" analyze out/study.db --out out/report
"$atonlab" analyze out/side_by_side.db --out out/report-side-by-side
echo "The study files are $(pwd)/out/study.db and $(pwd)/out/side_by_side.db (schema: docs/store.md)."
echo "Open the reports: $(pwd)/out/report/report.html (two intervals) and"
echo "  $(pwd)/out/report-side-by-side/report.html (side by side; docs/analysis.md)."
