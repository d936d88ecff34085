#!/bin/bash
# Regenerates docs/richefeu2009/: runs Richefeu et al.'s four samples (with the wetted-loose variants of
# the wet ones, and the dry ones again by contact dynamics) over three seeds each as sweeps,
# draws Fig. 7 (wet beside dry at 100 Pa) and the CD samples beside the MD ones, and copies
# the seed-5 figures and each sweep's ensemble.csv here. About 5 h of CPU (the CD samples
# about 17 and 30 min each), one core per run; two runs go at once on a 2-core machine.
# Finished points are kept: run it again to resume.
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release
G=target/release/grains
DOCS=docs/richefeu2009
for s in dry_iso_100pa dry_triaxial wet_iso_0pa wet_iso_100pa wet_iso_0pa_wetted_loose wet_iso_100pa_wetted_loose cd_iso_100pa cd_triaxial; do
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
# Contact dynamics' samples beside the MD ones (Figs. 2-3 by both methods).
"$G" analyze "$(runs cd_iso_100pa)" --beside "$(runs dry_iso_100pa)" > /dev/null
"$G" analyze "$(runs cd_triaxial)" --beside "$(runs dry_triaxial)" > /dev/null
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
cp "$(runs cd_iso_100pa)/force_pdf_beside.png" "$DOCS/fig2_cd_beside_md_force_pdf.png"
cp "$(runs cd_triaxial)/force_pdf_beside.png" "$DOCS/fig3_cd_beside_md_triaxial_force_pdf.png"
echo "figures and ensemble tables in $DOCS"
