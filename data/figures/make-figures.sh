#!/bin/sh
# make-figures.sh -- remakes every picture in data/figures (README figures).
# usage: sh data/figures/make-figures.sh [BUILD_DIR]   (from the repository
# root; BUILD_DIR defaults to build).  Needs gnuplot (gnuplot-nox).
set -eu
B=${1:-build}/jetfit
F=data/figures
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

# §6.1 convergence (Figs. 5-12): CSVs, gnuplot script and PNGs
"$B" convergence -o "$F/convergence"

# Fig. 1: the elliptic paraboloid z = 2x^2 + y^2, its two umbilics (+-1/4, 0)
"$B" generate paraboloid --mesh --n 5000 --seed 1 -o "$T/par.ply"
"$B" estimate "$T/par.ply" -o "$T/par-jets.ply" --neighbors rings \
    --orient viewpoint:0,0,100 --quiet
"$B" render "$T/par-jets.ply" -o "$F/paraboloid_umbilics.png" --color aniso \
    --directions --view top --glyphs 400 --size 600,520 --point-size 0.8 --small \
    --title "z = 2x^2 + y^2: (k1-k2)/(|k1|+|k2|), kmax red, kmin blue"

# Fig. 2: the surface of revolution z = 0.1 sin(10 r), parabolic lines K = 0
"$B" generate revolution --mesh --n 8000 --seed 1 -o "$T/rev.ply"
"$B" estimate "$T/rev.ply" -o "$T/rev-jets.ply" --neighbors rings --degree 3 \
    --orient viewpoint:0,0,100 --quiet
"$B" render "$T/rev-jets.ply" -o "$F/revolution_gauss.png" --color gauss \
    --directions --view top --glyphs 250 --size 600,520 --point-size 1.0 --small \
    --title "z = 0.1 sin(10 r): Gauss curvature (white: parabolic lines)"

# a raw Stanford bunny range scan coloured by mean curvature
"$B" estimate data/bun090.ply -o "$T/bun-jets.ply" --orient viewpoint:0,0,1 --quiet
"$B" render "$T/bun-jets.ply" -o "$F/bunny_mean.png" --color mean --view top \
    --size 600,560 --small --title "bun090 range scan: mean curvature (knn:32, degree 2)"
# docs/study.md: which neighbourhood at which noise level (jetfit study)
"$B" study ellipsoid -o "$T/study" --n 10000 --quiet \
    --neighbors 'knn:16;knn:32;knn:64;natural:32' --degree '2;3' \
    --noise '0;0.002;0.005;0.01' --repeat 2
cp "$T/study/normal.png" "$F/study_normal.png"
ls -l "$F"/*.png "$F"/convergence/*.png
