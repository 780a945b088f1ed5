# The three truths of the flowfield studies (scripts/flowfield-study.sh, flowfield-bands.sh):
# a store (sed expressions on the default scenario) and a [flowfield] table each. Sourced from
# the repository's root. `truth K` sets `store` and `field` to truth K's.
STORE_DEFAULT='s/^name = .*/name = "study"/'
STORE_STABLE='s/^cm_alpha_per_rad = .*/cm_alpha_per_rad = -0.5/;s/^cn_beta_per_rad = .*/cn_beta_per_rad = 0.5/;s/^cm_q_per_rad = .*/cm_q_per_rad = -120.0/'
STORE_LIGHT='s/^mass_kg = .*/mass_kg = 600.0/;s/^iyy_kg_m2 = .*/iyy_kg_m2 = 300.0/;s/^izz_kg_m2 = .*/izz_kg_m2 = 300.0/;s/^ixx_kg_m2 = .*/ixx_kg_m2 = 20.0/'

# Truth 1: the guide's example field (docs/model.md section 3b's conformance case).
FIELD_1=$(sed -n '/^\[flowfield\]/,$p' examples/flowfield-store/scenario.toml)
FIELD_2='[flowfield]
stations = 5
nose_x_m = 1.4
tail_x_m = -1.6
upwash_deg = 2.0
upwash_per_alpha = 0.8
upwash_gradient_deg_per_m = 0.5
sidewash_deg = 1.0
sidewash_per_alpha = 0.2
dynamic_pressure_ratio = 1.05
roll_cl = 0.01
half_depth_m = 1.2
reference_mach = 0.9'
FIELD_3='[flowfield]
stations = 7
nose_x_m = 1.2
tail_x_m = -1.3
upwash_deg = -1.0
upwash_per_alpha = 1.2
upwash_gradient_deg_per_m = -2.0
sidewash_deg = 0.5
dynamic_pressure_ratio = 0.95
half_depth_m = 0.5
reversal_m = 1.2
reference_mach = 0.95
reference_alpha_deg = 2.0'

truth() {
    case $1 in
        1) store=$STORE_DEFAULT field=$FIELD_1 ;;
        2) store=$STORE_STABLE field=$FIELD_2 ;;
        3) store=$STORE_LIGHT field=$FIELD_3 ;;
    esac
}
