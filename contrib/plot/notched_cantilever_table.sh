#!/bin/bash
# The table of doc/accuracy.md, "Accuracy after a cut": runs prm/notched_cantilever.prm
# with each of the four force models (the paper's springs, fitted springs, volume
# springs, corotated FEM) and prints, as a Markdown table, the springs' error against
# FEM P2 on the same mesh before the notch (uncut mesh) and after it (cut mesh), from
# the lines the 'fem comparison' postprocessor prints, with the tip deflection of the
# model and of FEM (the probe at the free end) from its comparison.csv.
#
#   bash contrib/plot/notched_cantilever_table.sh [build directory, default build]
#                                                 [extra parameter lines]
#
# The second argument, if given, is appended to every run's parameters (for instance
# 'subsection Mesh
#  subsection Box
#   set Repetitions = 10, 2, 2
#  end
# end' for the coarse mesh).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
extra=${2:-}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "| model | tets before / after | error L2 before | error L2 after | error max before | error max after | tip u_z before: model / FEM [mm] | tip u_z after: model / FEM [mm] |"
echo "|---|---|---|---|---|---|---|---|"
for entry in "paper springs|linear springs|paper" "fitted springs|linear springs|fitted" \
             "volume springs|volume springs|paper" "corotated fem|corotated fem|paper"; do
  IFS='|' read -r label model stiffness <<< "$entry"
  name=${label// /_}
  cat > "$work/$name.prm" <<PRM
include $root/prm/notched_cantilever.prm
set Output directory = $work/$name
subsection Force model
  set Model = $model
end
subsection Material
  set Spring stiffness = $stiffness
end
subsection Postprocess
  set List of postprocessors = fem comparison
end
$extra
PRM
  "$build/lacerta" "$work/$name.prm" > "$work/$name.log"
  lines=$(grep "^Static comparison" "$work/$name.log")
  [ "$(echo "$lines" | wc -l)" -eq 2 ] || { echo "$label: expected two comparisons" >&2; exit 1; }
  field() { echo "$lines" | sed -n "$1p" | sed -E "s/.*$2.*/\\1/"; }
  tets_before=$(field 1 'on ([0-9]+) tetrahedra')
  tets_after=$(field 2 'on ([0-9]+) tetrahedra')
  l2_before=$(field 1 'relative L2 ([^,]+),')
  l2_after=$(field 2 'relative L2 ([^,]+),')
  max_before=$(field 1 ', max ([^ ]+) of')
  max_after=$(field 2 ', max ([^ ]+) of')
  # comparison.csv: time, errors, then springs/FEM u_x, u_y, u_z of the tip probe.
  tip=$(awk -F, 'NR > 1 { printf "%s%.3f / %.3f", (NR > 2 ? " | " : ""), 1000 * $8, 1000 * $9 }' \
    "$work/$name/comparison.csv")
  printf "| %s | %s / %s | %.3g | %.3g | %.3g | %.3g | %s |\n" "$label" "$tets_before" \
    "$tets_after" "$l2_before" "$l2_after" "$max_before" "$max_after" "$tip"
done
