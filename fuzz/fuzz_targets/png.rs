//! The PNG height-map decoder under libFuzzer: see `knotwork::io::fuzz`.
#![no_main]

use knotwork::io::fuzz::{Target, check};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| check(Target::HeightImage, data));
