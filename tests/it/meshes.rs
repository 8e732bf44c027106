//! Meshes, packages, mass properties from geometry, and `restpose check`.
use approx::assert_abs_diff_eq;
use restpose::urdf::{load_file, ImportOptions};
use std::path::Path;
use std::process::Command;

/// A closed unit cube centred on the origin, as ASCII STL, OBJ and COLLADA.
fn write_cube_meshes(dir: &Path) {
    let v = [
        [-0.5, -0.5, -0.5],
        [0.5, -0.5, -0.5],
        [0.5, 0.5, -0.5],
        [-0.5, 0.5, -0.5],
        [-0.5, -0.5, 0.5],
        [0.5, -0.5, 0.5],
        [0.5, 0.5, 0.5],
        [-0.5, 0.5, 0.5],
    ];
    let f: [[usize; 3]; 12] = [
        [0, 2, 1],
        [0, 3, 2],
        [4, 5, 6],
        [4, 6, 7],
        [0, 1, 5],
        [0, 5, 4],
        [1, 2, 6],
        [1, 6, 5],
        [2, 3, 7],
        [2, 7, 6],
        [3, 0, 4],
        [3, 4, 7],
    ];
    let mut stl = String::from("solid cube\n");
    for t in &f {
        stl += "facet normal 0 0 0\nouter loop\n";
        for &i in t {
            stl += &format!("vertex {} {} {}\n", v[i][0], v[i][1], v[i][2]);
        }
        stl += "endloop\nendfacet\n";
    }
    stl += "endsolid cube\n";
    std::fs::write(dir.join("cube.stl"), stl).unwrap();
    let mut obj = String::new();
    for p in &v {
        obj += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for t in &f {
        obj += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    std::fs::write(dir.join("cube.obj"), obj).unwrap();
    let pos: Vec<String> = v
        .iter()
        .flat_map(|p| p.iter().map(|x| x.to_string()))
        .collect();
    let idx: Vec<String> = f
        .iter()
        .flat_map(|t| t.iter().map(|i| i.to_string()))
        .collect();
    let dae = format!(
        r##"<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
<asset><unit name="meter" meter="1"/><up_axis>Z_UP</up_axis></asset>
<library_geometries><geometry id="cube" name="cube"><mesh>
<source id="cube-pos"><float_array id="cube-pos-array" count="24">{}</float_array>
<technique_common><accessor source="#cube-pos-array" count="8" stride="3"><param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
<vertices id="cube-vtx"><input semantic="POSITION" source="#cube-pos"/></vertices>
<triangles count="12"><input semantic="VERTEX" source="#cube-vtx" offset="0"/><p>{}</p></triangles>
</mesh></geometry></library_geometries>
<library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#cube"/></node></visual_scene></library_visual_scenes>
<scene><instance_visual_scene url="#s"/></scene>
</COLLADA>"##,
        pos.join(" "),
        idx.join(" ")
    );
    std::fs::write(dir.join("cube.dae"), dae).unwrap();
}

fn arm(mesh: &str) -> String {
    format!(
        r#"<robot name="mesh_arm" xmlns:mech="urn:urdf-mech:1"><link name="world"/>
  <link name="arm"><collision><origin xyz="0.5 0 0"/><geometry><mesh filename="{mesh}" scale="0.2 0.2 0.2"/></geometry></collision>
    <visual><geometry><box size="1 0.1 0.1"/></geometry></visual></link>
  <joint name="j" type="revolute"><parent link="world"/><child link="arm"/><axis xyz="0 1 0"/></joint>
  <mech:joint_spring joint="j" stiffness="20"/></robot>"#
    )
}

/// A 0.2 m cube of density 1000 kg/m³ (8 kg) whose centre is at x = 0.5: the mass comes from
/// each mesh format and the arm balances 20 θ = 8 g 0.5 cos θ.
#[test]
fn inertia_from_mesh_geometry_in_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let pkg = dir.path().join("share").join("mypkg").join("meshes");
    std::fs::create_dir_all(&pkg).unwrap();
    write_cube_meshes(&pkg);
    let urdf_dir = dir.path().join("share").join("mypkg").join("urdf");
    std::fs::create_dir_all(&urdf_dir).unwrap();
    for ext in ["stl", "obj", "dae"] {
        // Found by walking up from the URDF's folder to `mypkg`.
        let file = urdf_dir.join(format!("arm_{ext}.urdf"));
        std::fs::write(&file, arm(&format!("package://mypkg/meshes/cube.{ext}"))).unwrap();
        let opts = ImportOptions {
            inertia_density: Some(1000.0),
            ..Default::default()
        };
        let l = load_file(&file, &opts).unwrap();
        assert!(l.warnings.is_empty(), "{ext}: {:?}", l.warnings);
        let b = &l.model.bodies()[0];
        assert_abs_diff_eq!(b.mass, 8.0, epsilon = 1e-9);
        assert_abs_diff_eq!(b.com.x, 0.5, epsilon = 1e-9);
        assert_abs_diff_eq!(b.com.z, 0.0, epsilon = 1e-9);
        // Inertia of a cube about its centre: m a² / 6.
        assert_abs_diff_eq!(b.inertia[(1, 1)], 8.0 * 0.04 / 6.0, epsilon = 1e-9);
        let (s, r) = restpose::solve(&l.model, &Default::default()).unwrap();
        assert!(r.converged());
        let th = s.joint_values(&l.model)[0].1[0];
        assert_abs_diff_eq!(20.0 * th, 8.0 * 9.81 * 0.5 * th.cos(), epsilon = 1e-8);
    }
    // The same through --package and through file://.
    let file = dir.path().join("elsewhere.urdf");
    std::fs::write(&file, arm("package://other/cube.stl")).unwrap();
    let opts = ImportOptions {
        inertia_density: Some(1000.0),
        packages: vec![("other".into(), pkg.clone())],
        ..Default::default()
    };
    assert_abs_diff_eq!(
        load_file(&file, &opts).unwrap().model.bodies()[0].mass,
        8.0,
        epsilon = 1e-9
    );
    std::fs::write(
        &file,
        arm(&format!("file://{}", pkg.join("cube.obj").display())),
    )
    .unwrap();
    let opts = ImportOptions {
        inertia_density: Some(1000.0),
        ..Default::default()
    };
    assert_abs_diff_eq!(
        load_file(&file, &opts).unwrap().model.bodies()[0].mass,
        8.0,
        epsilon = 1e-9
    );
}

/// `restpose check arm.urdf` run in the URDF's own folder (a relative path, as users type it):
/// the walk up for `package://mypkg/` goes on above the working directory and finds the
/// package, as it does from an absolute path (icub-models: every mesh was "not found" when the
/// model was named relative to its folder).
#[test]
fn a_package_above_the_working_directory_is_found_from_a_relative_path() {
    let dir = tempfile::tempdir().unwrap();
    let pkg = dir.path().join("mypkg");
    let meshes = pkg.join("meshes");
    let urdf_dir = pkg.join("robots").join("arm1");
    std::fs::create_dir_all(&meshes).unwrap();
    std::fs::create_dir_all(&urdf_dir).unwrap();
    write_cube_meshes(&meshes);
    std::fs::write(
        urdf_dir.join("arm.urdf"),
        arm("package://mypkg/meshes/cube.stl"),
    )
    .unwrap();
    for (cwd, path) in [
        (urdf_dir.clone(), "arm.urdf".to_string()),
        (pkg.join("robots"), "arm1/arm.urdf".to_string()),
        (pkg.join("robots"), "./arm1/../arm1/arm.urdf".to_string()),
    ] {
        let o = Command::new(env!("CARGO_BIN_EXE_restpose"))
            .current_dir(&cwd)
            .args([
                "check",
                &path,
                "--inertia-from-geometry",
                "1000",
                "--json",
                "-",
            ])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{path}: {err}");
        assert!(!err.contains("not found"), "{path}: {err}");
        let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let mass = j["bodies"][0]["mass"].as_f64().unwrap();
        assert_abs_diff_eq!(mass, 8.0, epsilon = 1e-9);
    }
}

/// A missing mesh is a warning with the file position, never an error or a panic; without
/// --inertia-from-geometry a link with no <inertial> stays massless.
#[test]
fn missing_mesh_is_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("arm.urdf");
    std::fs::write(&file, arm("package://nowhere/cube.stl")).unwrap();
    let l = load_file(&file, &ImportOptions::default()).unwrap();
    assert_eq!(l.model.bodies()[0].mass, 0.0);
    assert!(
        l.warnings.iter().any(|w| w.contains("arm.urdf:2:")
            && w.contains("mesh not found")
            && w.contains("nowhere")),
        "{:?}",
        l.warnings
    );
}

/// A mesh with a hole encloses no defined volume: --inertia-from-geometry still gives the link
/// a mass, and warns with the file position, the link, the mesh and how uncertain the volume
/// is (the cube without its top face: the area of the hole times the box diagonal over three,
/// against the volume the five faces left enclose from the vertex centroid).
#[test]
fn an_open_mesh_used_for_mass_is_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    write_cube_meshes(dir.path());
    let closed = std::fs::read_to_string(dir.path().join("cube.stl")).unwrap();
    // The two facets of the top face (z = 0.5 at every vertex) taken out.
    let facets: Vec<&str> = closed.split("facet normal").collect();
    let kept: Vec<&str> = facets
        .iter()
        .copied()
        .filter(|f| f.matches(" 0.5\n").count() < 3)
        .collect();
    assert_eq!(kept.len(), facets.len() - 2, "the top face's two facets");
    std::fs::write(dir.path().join("open.stl"), kept.join("facet normal")).unwrap();
    let file = dir.path().join("arm.urdf");
    std::fs::write(&file, arm("open.stl")).unwrap();
    let opts = ImportOptions {
        inertia_density: Some(1000.0),
        ..Default::default()
    };
    let l = load_file(&file, &opts).unwrap();
    assert!(l.model.bodies()[0].mass > 0.0);
    let w: Vec<&String> = l
        .warnings
        .iter()
        .filter(|w| w.contains("is not closed"))
        .collect();
    assert_eq!(w.len(), 1, "{:?}", l.warnings);
    assert!(
        w[0].contains("arm.urdf:2:") && w[0].contains("link `arm`") && w[0].contains("open.stl"),
        "{}",
        w[0]
    );
    // The uncertainty in percent, between 10 and 100 for a missing sixth of a cube.
    let pct: f64 = w[0]
        .split("up to ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|s| s.parse().ok())
        .unwrap();
    assert!((10.0..100.0).contains(&pct), "{pct}");
    // The closed cube: no such warning.
    std::fs::write(&file, arm("cube.stl")).unwrap();
    assert!(load_file(&file, &opts).unwrap().warnings.is_empty());
}

/// The library's warning for a missing package says what to do in library terms (no CLI
/// option); the CLI says it with its `--package` option, naming the package.
#[test]
fn missing_package_hint_is_the_library_s_and_the_cli_names_its_option() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("arm.urdf");
    std::fs::write(&file, arm("package://nowhere/cube.stl")).unwrap();
    let l = load_file(&file, &ImportOptions::default()).unwrap();
    let w = l
        .warnings
        .iter()
        .find(|w| w.contains("mesh not found"))
        .expect("a missing-mesh warning");
    assert!(w.contains(restpose::geometry::UNKNOWN_PACKAGE_HINT), "{w}");
    assert!(!w.contains("--"), "library warning names a CLI option: {w}");
    for sub in ["check", "analyze"] {
        let o = Command::new(env!("CARGO_BIN_EXE_restpose"))
            .args([sub, file.to_str().unwrap()])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            err.contains("mesh not found") && err.contains("use --package nowhere=DIR"),
            "{sub}: {err}"
        );
        assert!(
            !err.contains(restpose::geometry::UNKNOWN_PACKAGE_HINT),
            "{sub}: {err}"
        );
    }
}

/// `analyze -q --inertia-from-geometry` on a robot whose only mass was to come from a mesh
/// that is not found: the error (exit 1) says why nothing was weighed, though `-q` keeps the
/// import's warnings off standard error.
#[test]
fn inertia_from_geometry_that_weighs_nothing_says_why() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("arm.urdf");
    std::fs::write(
        &file,
        r#"<robot name="r"><link name="world"/>
  <link name="arm"><collision><geometry><mesh filename="package://nowhere/cube.stl"/></geometry></collision></link>
  <joint name="j" type="revolute"><parent link="world"/><child link="arm"/><axis xyz="0 1 0"/></joint></robot>"#,
    )
    .unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_restpose"))
        .args(["analyze", "-q", file.to_str().unwrap()])
        .args(["--inertia-from-geometry", "1000"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("is constant")
            && err.contains("could not weigh 1 link(s)")
            && err.contains("link `arm`: no mass from geometry")
            && err.contains("nowhere/cube.stl"),
        "{err}"
    );
}

#[test]
fn check_prints_the_model_and_json() {
    let urdf = format!("{}/robots/slider_crank.urdf", env!("CARGO_MANIFEST_DIR"));
    let o = Command::new(env!("CARGO_BIN_EXE_restpose"))
        .args(["check", &urdf, "--format", "json"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["dof"], 1);
    assert_eq!(v["bodies"].as_array().unwrap().len(), 3);
    let roles: Vec<&str> = v["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j["role"].as_str().unwrap())
        .collect();
    assert_eq!(roles, ["tree", "tree", "tree", "loop"]);
    let o = Command::new(env!("CARGO_BIN_EXE_restpose"))
        .args(["check", &urdf])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&o.stdout).contains("1 degrees of freedom"));
}

/// Meshes are read with a size cap: a (sparse) file over 256 MiB is refused before it is
/// read, with a warning naming the file and its size; the link stays massless.
#[test]
fn oversized_mesh_is_refused_without_reading_it() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("huge.stl");
    let f = std::fs::File::create(&mesh).unwrap();
    let len = restpose::geometry::MAX_MESH_BYTES + 1;
    f.set_len(len).unwrap();
    let file = dir.path().join("arm.urdf");
    std::fs::write(&file, arm("huge.stl")).unwrap();
    let opts = ImportOptions {
        inertia_density: Some(1000.0),
        ..Default::default()
    };
    let l = load_file(&file, &opts).unwrap();
    assert_eq!(l.model.bodies()[0].mass, 0.0);
    assert!(
        l.warnings.iter().any(|w| w.contains("huge.stl")
            && w.contains(&format!("{len} bytes"))
            && w.contains("256 MiB")),
        "{:?}",
        l.warnings
    );
}
