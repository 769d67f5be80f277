//! The boolean under libFuzzer, on two primitive solids the bytes place: see
//! `knotwork::io::fuzz`.
#![no_main]

use knotwork::io::fuzz::{Target, check};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| check(Target::Boolean, data));
