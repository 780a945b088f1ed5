#!/bin/sh
# The calibration table of `sepval predict` (docs/performance.md, "Predict"): every
# synthetic cause of predict/tests/calibration/cases.rs, two and three releases fitted, eight
# random cases each, the 95 % bands' coverage of the noise-free truth at another condition.
# About two minutes on two cores.
set -e
cd "$(dirname "$0")/.."
exec cargo test --release -p sepval-predict --test calibration -- --ignored --nocapture --exact table
