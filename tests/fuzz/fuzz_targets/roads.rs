#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| sim_fuzz::on_small_stack(|| sim_fuzz::roads(data)));
