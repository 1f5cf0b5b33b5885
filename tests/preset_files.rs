//! The invariant files shipped in `examples/presets/` describe exactly the presets.

// Needs invariant files: feature `toml`.
#![cfg(feature = "toml")]

use liemesh::generate;
use liemesh::io::invariant_file::InvariantFile;
use liemesh::model::LieField;
use liemesh::preset::Preset;
use std::path::PathBuf;

#[test]
fn every_preset_file_meshes_exactly_like_its_preset() {
    for preset in Preset::ALL {
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("examples/presets")
            .join(format!("{preset}.toml"));
        let file = InvariantFile::read(&path).unwrap_or_else(|e| panic!("{e}"));
        let params = file.params;
        assert_eq!(params, preset.params(), "{preset}: parameters");
        assert_eq!(
            file.invariant.numbers(),
            preset.invariant().numbers(),
            "{preset}: invariant"
        );
        let from_file = generate(&LieField::<f64>::new(&file.invariant), &params).unwrap();
        let from_preset =
            generate(&LieField::<f64>::new(&preset.invariant()), &preset.params()).unwrap();
        assert_eq!(from_file.triangles, from_preset.triangles, "{preset}");
        assert_eq!(from_file.vertices, from_preset.vertices, "{preset}");
    }
}
