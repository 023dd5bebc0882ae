//! The JSON constraint files of `subd edit` and `subd deform`: any bytes give constraints
//! or a typed error, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = subd_editing::spec::parse_constraints(text);
        let _ = subd_editing::spec::parse_deformation(text);
    }
});
