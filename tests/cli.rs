//! The command line as a user runs it.

// Needs the `liemesh` executable: feature `cli`.
#![cfg(feature = "cli")]

use std::path::{Path, PathBuf};
use std::process::Command;

fn liemesh() -> Command {
    Command::new(env!("CARGO_BIN_EXE_liemesh"))
}

/// A test's own folder under the system's temp folder, removed when the test ends, whether it
/// passes or fails (a run of the suite left a dozen folders behind each time).
struct Scratch(PathBuf);

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn scratch(name: &str) -> Scratch {
    let dir = std::env::temp_dir().join(format!("liemesh-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    Scratch(dir)
}

#[test]
fn every_preset_meshes_with_a_report() {
    let dir = scratch("presets");
    let mut triangles = Vec::new();
    for i in 1..=6 {
        let out = dir.join(format!("fig{i}.ply"));
        let report = dir.join(format!("fig{i}.json"));
        let status = liemesh()
            .args(["mesh", "--preset", &format!("fig{i}"), "-q", "-o"])
            .arg(&out)
            .arg("--report")
            .arg(&report)
            .status()
            .unwrap();
        assert!(status.success());
        let r: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
        for key in [
            "vertices",
            "triangles",
            "curves",
            "closed",
            "euler_characteristic",
            "boundary_loops",
            "seconds",
            "parameters",
        ] {
            assert!(r.get(key).is_some(), "report lacks {key}");
        }
        triangles.push(r["triangles"].as_u64().unwrap());
        assert!(std::fs::metadata(&out).unwrap().len() > 0);
    }
    assert!(
        triangles[0] < triangles[2] && triangles[2] < triangles[1],
        "{triangles:?}"
    );
    assert!(
        triangles[3] < triangles[5] && triangles[5] < triangles[4],
        "{triangles:?}"
    );
}

#[test]
fn no_arguments_meshes_fig6_into_out() {
    let dir = scratch("default");
    let o = liemesh().current_dir(&dir).output().unwrap();
    assert!(o.status.success());
    let text = String::from_utf8(o.stdout).unwrap();
    for word in ["vertices", "triangles", "curves", "time"] {
        assert!(text.contains(word), "summary lacks {word}: {text}");
    }
    assert!(dir.join("out/fig6.ply").exists());
}

/// The paper mode's explicit-Euler chords leave the surface (on a cone, past the apex onto
/// a hyperboloid: x² + y² − z² from 0 to −0.1 at the far end): the summary says how far, and
/// the drift-free default mode has no such line.
#[test]
fn the_paper_modes_drift_is_in_the_summary() {
    let drift_line = |mode: &str| {
        let o = liemesh()
            .args([
                "mesh",
                "--invariant",
                "examples/surfaces/cone.toml",
                "--mode",
                mode,
            ])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = String::from_utf8(o.stdout).unwrap();
        text.lines()
            .find(|l| l.trim_start().starts_with("drift"))
            .map(str::to_string)
    };
    let paper = drift_line("paper").expect("the paper mode's summary names its drift");
    let max: f64 = paper
        .split_whitespace()
        .nth(4)
        .and_then(|x| x.parse().ok())
        .unwrap_or_else(|| panic!("no number in {paper}"));
    assert!(max > 1e-3 && max < 1.0, "{paper}");
    assert_eq!(drift_line("default"), None);
}

#[test]
fn bad_input_exits_2_with_a_one_line_message() {
    let dir = scratch("bad");
    let o = liemesh()
        .args(["mesh", "--preset", "fig3", "--dt", "-1", "-o"])
        .arg(dir.join("x.ply"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8(o.stderr).unwrap();
    assert!(
        err.contains("dt") && err.trim().lines().count() == 1,
        "{err}"
    );

    let o = liemesh()
        .args(["mesh", "--preset", "fig3", "-o"])
        .arg(dir.join("x.xyz"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));

    let file = dir.join("bad.toml");
    std::fs::write(
        &file,
        "invariant = [1, 1, 1, 0, 0, 0]\n[mesh]\nmethod = \"fast\"\n",
    )
    .unwrap();
    let o = liemesh()
        .args(["mesh", "--invariant"])
        .arg(&file)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8(o.stderr).unwrap();
    assert!(
        err.contains("bad.toml") && err.contains("fast") && err.contains("`previous`"),
        "{err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{err}");

    // A NaN, from a flag or from the file, is named (it once reached a JSON conversion as
    // null: "invalid type: null").
    let o = liemesh()
        .args(["mesh", "--preset", "fig3", "--p0", "nan,0,0", "-o"])
        .arg(dir.join("x.ply"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8(o.stderr).unwrap();
    assert!(err.contains("--p0") && err.contains("finite"), "{err}");
    std::fs::write(
        &file,
        "invariant = [1, 1, 1, 0, 0, 0]\n[mesh]\np0 = [nan, 0, 0]\n",
    )
    .unwrap();
    let o = liemesh()
        .args(["mesh", "--invariant"])
        .arg(&file)
        .arg("-o")
        .arg(dir.join("x.ply"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8(o.stderr).unwrap();
    assert!(err.contains("p0.x") && err.contains("NaN"), "{err}");
}

#[test]
fn each_error_is_printed_once() {
    let dir = scratch("once");
    let good = dir.join("good.toml");
    std::fs::write(
        &good,
        "invariant = [1, 4, 16, 0, 0, 0]\n[mesh]\np0 = [0.0, 0.0, 0.25]\ndt = 0.05\n",
    )
    .unwrap();
    let bad = dir.join("bad.toml");
    std::fs::write(
        &bad,
        "invariant = [1, 1, 1, 0, 0, 0]\n[mesh]\nmethod = \"fast\"\n",
    )
    .unwrap();
    // The message names the unknown value; it must show once in stdout and stderr together.
    let once = |o: &std::process::Output| {
        let (out, err) = (
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr),
        );
        let n = out.matches("`previous`").count() + err.matches("`previous`").count();
        assert_eq!(n, 1, "stdout:\n{out}\nstderr:\n{err}");
        (out.into_owned(), err.into_owned())
    };

    let o = liemesh()
        .arg("batch")
        .args([&good, &bad])
        .arg("-o")
        .arg(dir.join("out"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let (out, err) = once(&o);
    // The table marks the input; standard error says what was wrong with it.
    let row = out.lines().find(|l| l.contains("bad.toml")).unwrap();
    assert!(row.trim_end().ends_with("FAILED"), "{out}");
    assert!(out.contains("1 meshed, 1 failed"), "{out}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("bad.toml") && err.contains("fast"), "{err}");

    // --quiet keeps the errors.
    let o = liemesh()
        .args(["batch", "--quiet"])
        .arg(&bad)
        .arg("-o")
        .arg(dir.join("out"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let (out, _) = once(&o);
    assert!(out.is_empty(), "{out}");

    // The other commands print their error once, on standard error.
    for command in ["mesh", "audit", "quality"] {
        let o = liemesh()
            .args([command, "--invariant"])
            .arg(&bad)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{command}");
        let (out, _) = once(&o);
        assert!(out.is_empty(), "{command}: {out}");
    }
}

/// A batch row says what `liemesh mesh` says of the same run: a run cut short by a budget is
/// INCOMPLETE there too, not a finished mesh.
#[test]
fn batch_says_which_runs_were_cut_short() {
    let dir = scratch("batch-budget");
    let budget = dir.join("budget.toml");
    std::fs::write(
        &budget,
        "invariant = [1, 4, 16, 0, 0, 0]\n[mesh]\np0 = [0.6, 0.4, 0.0]\nmax_points = 500\n",
    )
    .unwrap();
    let o = liemesh()
        .arg("batch")
        .arg(&budget)
        .arg("-o")
        .arg(dir.join("out"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("INCOMPLETE the point budget (max_points = 500) ran out"),
        "{out}"
    );
    let single = liemesh()
        .args(["mesh", "--invariant"])
        .arg(&budget)
        .arg("-o")
        .arg(dir.join("single.ply"))
        .output()
        .unwrap();
    let single = String::from_utf8_lossy(&single.stdout);
    assert!(single.contains("INCOMPLETE the point budget"), "{single}");
}

/// Arguments that cannot work together are refused before any meshing: from a singular
/// `p0`, whose run would fail first, the error is the arguments', not the run's.
#[test]
fn conflicting_arguments_are_refused_before_meshing() {
    let dir = scratch("conflicts");
    let singular = dir.join("singular.toml");
    std::fs::write(
        &singular,
        "invariant = [1, 1, 1, 0, 0, 0]\n[mesh]\np0 = [0, 0, 0]\n",
    )
    .unwrap();
    let a_file = dir.join("a-file");
    std::fs::write(&a_file, "").unwrap();
    let in_file = a_file.join("x.ply");
    let x = |name: &str| dir.join(name).to_string_lossy().into_owned();
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec!["-o".into(), x("x.stl"), "--derivative".into(), "1".into()],
            "give an output ending in .ply",
        ),
        (
            vec![
                "-o".into(),
                x("x.ply"),
                "--derivative".into(),
                "1".into(),
                "--scalar".into(),
                "f32".into(),
            ],
            "leave out --scalar",
        ),
        (
            vec!["-o".into(), x("x.ply"), "--derivative".into(), "7".into()],
            "the invariant has 6 numbers",
        ),
        (
            vec!["-o".into(), in_file.to_string_lossy().into_owned()],
            "is a file, not a folder",
        ),
        (
            vec!["-o".into(), x("x.ply"), "--png".into(), x("x.jpg")],
            "must end in .png or .svg",
        ),
    ];
    for (args, says) in cases {
        let o = liemesh()
            .args(["mesh", "--invariant"])
            .arg(&singular)
            .args(&args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains(says) && !err.contains("singular"),
            "{args:?}: {err}"
        );
    }
}

#[test]
fn a_failed_run_still_writes_its_report_saying_why() {
    let dir = scratch("failed");
    let file = dir.join("singular.toml");
    std::fs::write(
        &file,
        "invariant = [1, 1, 1, 0, 0, 0]\n[mesh]\np0 = [0, 0, 0]\n",
    )
    .unwrap();
    let (mesh, report) = (dir.join("x.ply"), dir.join("r.json"));
    let o = liemesh()
        .args(["mesh", "--invariant"])
        .arg(&file)
        .arg("-o")
        .arg(&mesh)
        .arg("--report")
        .arg(&report)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("singular point"), "{err}");
    assert!(!mesh.exists(), "no mesh is written for a failed run");
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert!(
        r["error"].as_str().unwrap().contains("singular point"),
        "{r}"
    );
    assert_eq!(r["parameters"]["p0"], serde_json::json!([0.0, 0.0, 0.0]));
    assert_eq!(r["invariant"].as_array().unwrap().len(), 6);
    assert!(r.get("triangles").is_none(), "{r}");

    // --json prints the same report on standard output.
    let o = liemesh()
        .args(["mesh", "--json", "--invariant"])
        .arg(&file)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let printed: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(printed, r);
}

#[test]
fn an_invariant_file_meshes_an_ellipsoid_in_every_format() {
    let dir = scratch("ellipsoid");
    let file = dir.join("ellipsoid.toml");
    std::fs::write(
        &file,
        "invariant = [1, 4, 16, 0, 0, 0]\n[mesh]\np0 = [0.0, 0.0, 0.25]\ndt = 0.05\n",
    )
    .unwrap();
    for ext in ["ply", "obj", "stl"] {
        let out = dir.join(format!("e.{ext}"));
        let status = liemesh()
            .args(["mesh", "-q", "--invariant"])
            .arg(&file)
            .arg("-o")
            .arg(&out)
            .status()
            .unwrap();
        assert!(status.success(), "{ext}");
        assert!(std::fs::metadata(&out).unwrap().len() > 100);
    }
}

#[test]
fn json_prints_the_report_with_its_quality_section() {
    let o = liemesh()
        .args(["mesh", "--preset", "fig3", "--json"])
        .output()
        .unwrap();
    assert!(o.status.success());
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).expect("stdout is JSON");
    assert_eq!(r["closed"], true);
    let q = &r["quality"];
    for key in [
        "shape",
        "steps",
        "face_normal_error_max",
        "drift",
        "recovery",
        "topology",
    ] {
        assert!(q.get(key).is_some(), "quality lacks {key}");
    }
}

#[test]
fn audit_and_quality_take_invariant_files() {
    let file = "examples/surfaces/cubic.toml";
    let out = liemesh()
        .args(["audit", "--invariant", file])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    assert!(
        text.contains("mesh valid") && text.contains("cubic"),
        "{text}"
    );
    assert!(
        text.contains("prediction order") && text.contains(" 0 failed"),
        "{text}"
    );

    let out = liemesh()
        .args(["quality", "--invariant", file])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    assert!(text.contains("| cubic | default | 6134 |"), "{text}");

    // A file that is not there: a clear error, exit 2 as for any bad input.
    let out = liemesh()
        .args(["audit", "--invariant", "no/such/file.toml"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("no/such/file.toml"));
}

#[test]
fn derivatives_are_written_as_ply_properties_and_in_the_report() {
    let dir = scratch("derivatives");
    let (ply, json) = (dir.join("fig3.ply"), dir.join("fig3.json"));
    let status = liemesh()
        .args([
            "mesh",
            "--preset",
            "fig3",
            "--derivative",
            "2",
            "-q",
            "--ascii",
            "-o",
        ])
        .arg(&ply)
        .arg("--report")
        .arg(&json)
        .status()
        .unwrap();
    assert!(status.success());
    let text = std::fs::read_to_string(&ply).unwrap();
    assert!(
        text.contains("property double d_n2_x\nproperty double d_n2_y\nproperty double d_n2_z\n")
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let d = &report["derivatives"][0];
    assert_eq!(d["number"], 2);
    assert_eq!(
        d["values"].as_array().unwrap().len(),
        report["vertices"].as_u64().unwrap() as usize
    );
    assert!(d["max_norm"].as_f64().unwrap() > 0.1);
    // The file still reads as a mesh (readers skip properties they do not know).
    let mesh = liemesh::io::read_mesh(&ply).unwrap();
    assert_eq!(mesh.vertices.len(), d["values"].as_array().unwrap().len());
    // Bad numbers and formats are usage errors.
    for args in [
        ["--derivative", "19", "-o", "x.ply"],
        ["--derivative", "2", "-o", "x.obj"],
    ] {
        let out = liemesh()
            .args(["mesh", "--preset", "fig3", "-q"])
            .args(args)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
    }
}
