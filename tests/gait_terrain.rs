//! Walking on uneven ground: every stance foot stands on the terrain
//! (`y = ϱ(x, z)`), for the shipped slope example, on a sine terrain and on
//! the random height map of examples/hexapod_rough.toml.

use std::path::Path;
use std::sync::atomic::AtomicBool;

use fbd_cli::config::{self, Config, Override};
use fbd_sim::gait::run_gait;

fn check(path: &Path, overrides: &[Override]) -> usize {
    let Config::Hexapod(h) = config::load_with_overrides(path, overrides).unwrap() else {
        panic!("a hexapod configuration")
    };
    let m = h.gait_model("test").unwrap();
    let mut checked = 0;
    let s = run_gait(&m, &AtomicBool::new(false), |d| {
        for (leg, down) in d.stance().iter().enumerate() {
            if *down {
                let f = d.fk.legs[leg].tip;
                let gap = f.y - m.surface.height(f.x, f.z);
                assert!(
                    gap.abs() < 1e-9,
                    "t {} leg {}: {gap:e} m off the terrain",
                    d.t,
                    leg + 1
                );
                checked += 1;
            }
        }
    });
    assert!(s.error.is_none(), "{:?}", s.error);
    checked
}

#[test]
fn stance_feet_stand_on_the_slope() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/hexapod_wave_slope.toml");
    assert!(check(&p, &[]) > 8000);
}

#[test]
fn stance_feet_stand_on_a_sine_terrain() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/hexapod_tripod.toml");
    let o = [
        Override::parse("terrain.kind=\"sine\"").unwrap(),
        Override::parse("terrain.amplitude=0.03").unwrap(),
        Override::parse("terrain.wavelength=0.8").unwrap(),
        Override::parse("initial.phi_deg=[0.0, -90.0, 0.0]").unwrap(),
        Override::parse("time.duration=5.0").unwrap(),
        Override::parse("gait.walk_time=4.0").unwrap(),
    ];
    assert!(check(&p, &o) > 1500);
}

#[test]
fn stance_feet_stand_on_a_random_height_map() {
    // examples/hexapod_rough.toml's ground under the kinematic tripod gait.
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/hexapod_rough.toml"),
    )
    .unwrap();
    let kinematic = text[..text.find("[control]").unwrap()].replace("dt = 0.001", "dt = 0.01");
    let dir = std::env::temp_dir().join(format!("fbd_gait_terrain_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("rough.toml");
    std::fs::write(&p, kinematic).unwrap();
    let n = check(&p, &[]);
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(n > 3000, "{n} stance rows checked");
}
