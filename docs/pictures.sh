#!/bin/sh
# The pictures of the README and the guide, each made by Poinsot's own command (`make pictures`
# runs this with .venv/bin first on the PATH). Then `poinsot report` for the guide's
# work-precision figure.
set -eu
cd "$(dirname "$0")/.."
poinsot screenshot --preset t_handle --out assets/t_handle_flip.png
poinsot video --preset t_handle --from 4 --seconds 6 --fps 12 --size 480x270 --out assets/t_handle.gif
poinsot screenshot --preset t_handle --strobe 8 --size 1280x720 --out assets/t_handle_strobe.png
for scene in polhode-family dzhanibekov symmetric-top gyroscope-torque long-cylinder \
    explorer-1 geometric-phase tennis-racket; do
    poinsot screenshot --scene "$scene" --size 1280x800 --out "assets/scenes/$scene.png"
done
python tests/browser/page_pictures.py      # assets/page/*.png (every size, both themes), assets/drag_1280x800.png
poinsot report --quick --out build/pictures-report
cp build/pictures-report/work_precision.png assets/report/work_precision.png
