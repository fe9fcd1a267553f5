#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| sim_fuzz::on_small_stack(|| sim_fuzz::scenario(data)));
libfuzzer_sys::fuzz_mutator!(|data: &mut [u8], size: usize, max_size: usize, seed: u32| {
    sim_fuzz::mutate_scenario(data, size, max_size, seed)
});
