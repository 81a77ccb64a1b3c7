//! `main` of a test binary built without libtest's harness (`harness =
//! false` in `Cargo.toml`): the allocation tests, whose counters are
//! process-global while the harness's main thread allocates as it waits
//! for a test to finish, at a moment no test controls.

/// Runs `test` alone, as test `name`. `--list` answers as libtest does,
/// for cargo-nextest.
pub fn run_alone(name: &str, test: fn()) {
    let args: Vec<String> = std::env::args().collect();
    if args.iter().any(|a| a == "--list") {
        if !args.iter().any(|a| a == "--ignored") {
            println!("{name}: test");
        }
        return;
    }
    test();
    println!("test {name} ... ok");
}
