//! Fuzzes the configuration loader: any input is accepted or rejected
//! with a one-line error, never a panic; an accepted configuration builds
//! its model and round-trips through `config.toml`.
#![no_main]

use fbd_cli::Config;
use fbd_cli::config::parse_str;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match parse_str(text, "fuzz.toml", &[]) {
        Err(e) => assert!(!e.to_string().contains('\n'), "multi-line error: {e}"),
        Ok(c) => {
            let written = c.to_toml();
            let again = parse_str(&written, "config.toml", &[]);
            assert_eq!(again.as_ref().ok(), Some(&c), "{again:?}\n{written}");
            if let Config::Planar(p) = &c {
                let _ = p.model("fuzz.toml");
            }
        }
    }
});
