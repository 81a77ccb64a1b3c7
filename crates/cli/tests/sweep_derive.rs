//! The sweep format's array ranges (random mode) and `[derive]` keys.

use fbd_cli::sweep::{SweepFile, expand};

fn sweep(text: &str) -> Result<Vec<Vec<toml::Value>>, String> {
    let file: SweepFile = toml::from_str(text).expect("sweep file parses");
    expand(&file, "s.toml")
}

#[test]
fn array_ranges_draw_every_component_and_derive_scales() {
    let runs = sweep(
        "mode = \"random\"\nsamples = 50\nseed = 3\n[vary]\n\"terrain.mu_static\" = { min = 0.2, max = 1.2 }\n\"initial.leg3.theta_deg\" = { min = [-20.0, 225.0], max = [20.0, 265.0] }\n[derive]\n\"terrain.mu_dynamic\" = { from = \"terrain.mu_static\", scale = 0.75 }\n",
    )
    .unwrap();
    assert_eq!(runs.len(), 50);
    let mut distinct = std::collections::BTreeSet::new();
    for r in &runs {
        assert_eq!(r.len(), 3, "two varied keys and one derived");
        let mus = r[0].as_float().unwrap();
        assert!((0.2..1.2).contains(&mus));
        let theta = r[1].as_array().unwrap();
        let (t2, t3) = (theta[0].as_float().unwrap(), theta[1].as_float().unwrap());
        assert!((-20.0..20.0).contains(&t2) && (225.0..265.0).contains(&t3));
        assert_eq!(r[2].as_float().unwrap(), 0.75 * mus);
        distinct.insert(t3.to_bits());
    }
    assert_eq!(distinct.len(), 50, "every run draws its own angles");
}

#[test]
fn bad_derive_and_array_ranges_name_the_key() {
    for (text, needle) in [
        (
            "mode = \"grid\"\n[vary]\n\"terrain.mu_static\" = [0.3]\n[derive]\n\"terrain.mu_dynamic\" = { from = \"terrain.height\", scale = 0.5 }\n",
            "derive.\"terrain.mu_dynamic\"",
        ),
        (
            "mode = \"grid\"\n[vary]\n\"terrain.mu_static\" = [0.3]\n[derive]\n\"terrain.mu_dynamic\" = { scale = 0.5 }\n",
            "derive.\"terrain.mu_dynamic\"",
        ),
        (
            "mode = \"random\"\nsamples = 2\n[vary]\n\"initial.position\" = { min = [0.0, 0.5], max = [0.0] }\n",
            "vary.\"initial.position\"",
        ),
    ] {
        let e = sweep(text).unwrap_err();
        assert!(e.starts_with("s.toml: ") && e.contains(needle), "{e}");
    }
}
