//! The integration tests that need the simulator (feature `sim`) or image files, in one
//! binary (`cargo test --test sim`; one file's: `cargo test --test sim krawler_state::`).
//! One module per file beside this one.

mod common;

mod apriltag_photos;
mod autokrawler_world;
mod avoid_profile;
mod axel_closed_loop;
mod axel_reel;
mod axel_world;
mod bujold_closed_loop;
mod bujold_raposa;
mod camera_encodings;
mod camera_imperfections;
mod circles_pose;
mod circles_render;
mod dock_judge;
mod endurance;
mod fuzz_regressions;
mod krawler_loop;
mod krawler_markers;
mod krawler_state;
mod krawler_steering;
mod krawler_wheels;
mod mcap_record;
mod optical_flow;
mod paint_sct;
mod pyramid_imprint;
mod pyramid_render;
mod raposa_closed_loop;
mod real_photos;
mod sim_faults;
mod sim_render;
mod sim_scripted;
mod two_block_pose_render;
