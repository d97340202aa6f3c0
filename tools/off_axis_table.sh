#!/bin/bash
# The off-axis table of docs/validation.md: refraction and coma of an eye across the horizontal
# field, one `ocular eye measure --field-deg` per row.
#   tools/off_axis_table.sh [EYE] [PUPIL_MM] [WAVELENGTH_NM]
set -euo pipefail
eye=${1:-navarro-wide}
pupil=${2:-4}
wl=${3:-555}
bin=${OCULAR:-target/release/ocular}
echo "| field | M (D) | J0 (D) | c(3,1) µm | ellipse (mm) |"
echo "|---|---|---|---|---|"
for h in 0 10 20 30 40 50; do
  "$bin" eye measure "$eye" --pupil-mm "$pupil" --wavelength-nm "$wl" --field-deg "$h,0" --json |
    jq -r --arg h "$h" '"| \($h)° | \(.refraction.m*1000|round/1000) | \(.refraction.j0*1000|round/1000) | \((.coefficients[] | select(.n==3 and .m==1) | .um)*10000|round/10000) | \(.field.semi_axes_mm[0]*2*1000|round/1000) × \(.field.semi_axes_mm[1]*2*1000|round/1000) |"'
done
