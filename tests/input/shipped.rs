//! Every shipped scene (`problems/*.toml`) passes `mpm check`: it parses,
//! validates and builds (its files, the fill of its bodies, the memory
//! estimate). The limit-analysis files take `mpm limit` and are left out
//! (`other_kinds_of_file_get_a_hint` covers them).

use std::process::Command;

#[test]
fn every_shipped_scene_passes_mpm_check() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("problems");
    let mut scenes: Vec<std::path::PathBuf> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .filter(|p| {
            !p.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("limit_")
        })
        .collect();
    scenes.sort();
    assert!(scenes.len() > 40, "{} scenes", scenes.len());
    for scene in &scenes {
        let out = Command::new(env!("CARGO_BIN_EXE_mpm"))
            .arg("check")
            .arg(scene)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "mpm check {}: {}",
            scene.display(),
            String::from_utf8_lossy(&out.stderr)
        );
    }
}
