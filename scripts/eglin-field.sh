# Sourced by the Eglin scripts (eglin-conditions.sh, eglin-field-shape.sh): `eglin_field BASE
# OUT` writes to OUT the default scenario BASE with t_end 0.5 s (as the CFD) and the aircraft's
# flowfield in place of the decay increments: the default's interference at carriage (upwash
# 5.99 deg, its gradient -10.4 deg/m, sidewash -5.84 deg, 4.28 deg/m, eta 1.09, roll -0.03),
# halving 0.42 m below it (as exp(-s / 0.6)), the interference factors' bounds widened to
# [-1, 3] (docs/eglin-cfd.md, "The flowfield's shape on this release").
eglin_field() {
    sed -E -e 's/^t_end_s = .*/t_end_s = 0.5/' -e 's/^(dc[xyzlmn]0) = .*/\1 = 0.0/' \
        -e 's/^(c[aymnlz]intfac) = .*/\1 = { min = -1.0, max = 3.0, bits = 8 }/' "$1" > "$2"
    cat >> "$2" <<'FIELD'

[flowfield]
stations = 5
nose_x_m = 1.5
tail_x_m = -1.5
upwash_deg = 5.99
upwash_gradient_deg_per_m = -10.4
sidewash_deg = -5.84
sidewash_gradient_deg_per_m = 4.28
dynamic_pressure_ratio = 1.09
roll_cl = -0.03
half_depth_m = 0.42
reference_mach = 0.95
FIELD
}
