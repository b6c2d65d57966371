#!/bin/bash
# Renders the paper's Figures 8 to 11 from Lacerta's scenes with the png postprocessor
# (doc/viewer.md) into doc/images/figure-*.png: the square pulled and cut, the punched
# hole, the kidney's cuts on the level of detail, the tear. Each scene runs to its end
# time; the picture of the last state is kept. Then the manual's screenshot of
# lacerta-view (doc/images/lacerta-view.png) and doc/accuracy.md's springs against FEM
# (doc/images/square_pull_comparison.png; needs python3-vtk9).
#
#   bash contrib/figures/render_paper_figures.sh [build directory, default build]
#
# Needs an X display; without one it runs itself under xvfb-run.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
if [ -z "${DISPLAY:-}" ]; then
  exec xvfb-run -a -s "-screen 0 1280x1024x24" bash "$0" "$build"
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# The End time a parameter file sets, itself or through the files it includes.
end_time() {
  local file=$1 value included
  value=$( (grep -h "^set End time" "$file" || true) | tail -1 | sed 's/.*= *//')
  if [ -z "$value" ]; then
    for included in $( (grep "^include " "$file" || true) | sed 's/^include *//'); do
      value=$(end_time "$(dirname "$file")/$included")
    done
  fi
  echo "$value"
}

# render <figure> <scene> <field> <wireframe> <title> [<colour range 'low, high'>]
render() {
  local figure=$1 scene=$2 field=$3 wireframe=$4 title=$5 range=${6:-}
  local end
  end=$(end_time "$root/prm/$scene.prm")
  cat > "$work/$scene.prm" <<PRM
include $root/prm/$scene.prm
set Output directory = $work/$scene
subsection Postprocess
  set List of postprocessors = png
  subsection Png
    set Time between pictures = ${end:-1}
    set Field                 = $field
    set Wireframe             = $wireframe
    set Title                 = $title
    set Colour range          = $range
    set Width                 = 800
    set Height                = 600
  end
end
PRM
  echo "$figure: $scene"
  "$build/lacerta" "$work/$scene.prm" > "$work/$scene.log"
  local last
  last=$(ls "$work/$scene"/picture-*.png | sort | tail -1)
  cp "$last" "$root/doc/images/$figure-$scene.png"
}

render figure-8 square_cut displacement false "Figure 8: the pulled square cut partially"
render figure-9 square_hole displacement false "Figure 9: a square punched out" "0, 0.02"
render figure-10 kidney_cut "cell size" true "Figure 10: cuts on the level of detail"
render figure-11 square_tear "spring strain" false "Figure 11: a laceration" "-0.2, 1"

# The manual's screenshot of lacerta-view: a stroke dragged through the pulled slab in
# real time, the wireframe on, the blade still in the tissue.
cat > "$work/viewer.prm" <<PRM
include $root/prm/square_pull.prm
subsection Viewer
  set Speed = 1
  set Field = displacement
end
PRM
cat > "$work/viewer_events.txt" <<EVENTS
0.3 press 0.3 0.5
0.5 move 0.4 0.5
0.7 move 0.5 0.5
0.9 move 0.6 0.5
1.1 move 0.68 0.5
1.3 key w
1.6 screenshot $root/doc/images/lacerta-view.png
1.61 release
1.62 quit
EVENTS
echo "lacerta-view screenshot: square_pull"
(cd "$work" && "$build/lacerta-view" --size 900x600 --events viewer_events.txt \
  viewer.prm > viewer.log)

# doc/accuracy.md's springs against FEM on prm/square_pull_comparison.prm, side by side
# on one colour scale: the `fem comparison` postprocessor writes its fields at t = 0.5 s,
# the end of the pull, and render_comparison.py (python3-vtk9) draws them.
cat > "$work/comparison.prm" <<PRM
include $root/prm/square_pull_comparison.prm
set Output directory = $work/output
set End time         = 0.5
subsection Postprocess
  subsection Fem comparison
    set Time between fields   = 0.5
    set Number of frequencies = 0
  end
end
PRM
echo "springs against FEM: square_pull_comparison"
"$build/lacerta" "$work/comparison.prm" > "$work/comparison.log"
grep "Comparison at t = 0.5 s" "$work/comparison.log"
/usr/bin/python3 "$root/contrib/figures/render_comparison.py" \
  "$work/output/comparison-00001.vtu" "$root/doc/images/square_pull_comparison.png" \
  "square_pull_comparison at t = 0.5 s: springs and FEM P2 on the same 60 tetrahedra"
echo "Pictures in $root/doc/images/: figure-*.png, lacerta-view.png, square_pull_comparison.png"
