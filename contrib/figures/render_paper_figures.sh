#!/bin/bash
# Renders the paper's Figures 8 to 11 from Lacerta's scenes with the png postprocessor
# (doc/viewer.md) into doc/images/figure-*.png: the square pulled and cut, the punched
# hole, the kidney's cuts on the level of detail, the tear. Each scene runs to its end
# time; the picture of the last state is kept.
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
echo "Pictures in $root/doc/images/figure-*.png"
