//! One file per fixed bug: `issue_<n>_<what>.rs`, opening with a paragraph on the bug.

mod issue_12_assembly_names_the_joint;
mod issue_12_sparse_verify_angle_branch;
mod issue_13_floating_base_start;
mod issue_21_bolt_rolls_over;
mod issue_21_chain_on_its_stops;
mod issue_21_curved_valley;
mod issue_21_falls_found_at_once;
mod issue_21_free_arm_converges_directly;
mod issue_21_ground_start;
mod issue_21_knees_on_both_stops;
mod issue_21_legs_up_fall_at_once;
mod issue_21_neutral_yaw_converges;
mod issue_21_newton_along_the_path;
mod issue_21_stand_from_reference;
mod issue_21_stops_leave_together;
mod issue_21_verify_forces_and_stability;
mod issue_22_off_the_ramp;
mod issue_25_closed_pipe;
mod issue_25_fuzz_smoke;
mod issue_25_located_errors;
mod issue_25_unbounded_numbers;
mod issue_25_verify_agrees_with_analyze;
mod issue_26_rope_rounds;
