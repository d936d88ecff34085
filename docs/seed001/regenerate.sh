#!/bin/bash
# Regenerates docs/seed001/: runs seed 001's four samples (and the wetted-loose variants of
# the wet ones) over three seeds each as sweeps, draws Fig. 7 (wet beside dry at 100 Pa), and
# copies the seed-5 figures and each sweep's ensemble.csv here. About 3 h of CPU, one core per
# run; two runs go at once on a 2-core machine. Finished points are kept: run it
# again to resume.
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release
G=target/release/grains
DOCS=docs/seed001
for s in dry_iso_100pa dry_triaxial wet_iso_0pa wet_iso_100pa wet_iso_0pa_wetted_loose wet_iso_100pa_wetted_loose; do
  "$G" sweep "scenes/seeds/$s.toml" --jobs 2 --threads 1
  cp "scenes/seeds/$s-runs/ensemble.csv" "$DOCS/$s.csv"
done
runs() { echo "scenes/seeds/$1-runs/point-000"; }
# Re-analyse the seed-5 samples with this build (the pictures), Fig. 7 beside the dry one.
"$G" analyze "$(runs dry_iso_100pa)" > /dev/null
"$G" analyze "$(runs dry_triaxial)" > /dev/null
"$G" analyze "$(runs wet_iso_0pa)" > /dev/null
"$G" analyze "$(runs wet_iso_100pa)" --beside "$(runs dry_iso_100pa)" > /dev/null
"$G" analyze "$(runs wet_iso_0pa_wetted_loose)" > /dev/null
cp "$(runs dry_iso_100pa)/force_pdf.png" "$DOCS/fig2_dry_force_pdf.png"
cp "$(runs dry_triaxial)/force_pdf.png" "$DOCS/fig3_triaxial_force_pdf.png"
cp "$(runs wet_iso_0pa)/force_network.png" "$DOCS/fig5a_wet_0pa_force_network.png"
cp "$(runs wet_iso_100pa)/force_network.png" "$DOCS/fig5b_wet_100pa_force_network.png"
cp "$(runs wet_iso_0pa)/force_pdf.png" "$DOCS/fig6_wet_0pa_force_pdf.png"
cp "$(runs wet_iso_100pa)/force_pdf_beside.png" "$DOCS/fig7_wet_beside_dry_100pa.png"
cp "$(runs wet_iso_0pa)/pressure_pdf.png" "$DOCS/fig8_wet_0pa_pressure_pdf.png"
cp "$(runs wet_iso_0pa)/pressure_map.png" "$DOCS/fig9_wet_0pa_pressure_map.png"
cp "$(runs wet_iso_0pa_wetted_loose)/force_pdf.png" "$DOCS/variant_wetted_loose_0pa_force_pdf.png"
cp "$(runs wet_iso_0pa_wetted_loose)/force_network.png" "$DOCS/variant_wetted_loose_0pa_force_network.png"
echo "figures and ensemble tables in $DOCS"
