//! End-to-end: `facette render` on Mitsuba 3 XML scenes, `-D name=value`, warnings and
//! errors.

use facette_render::image::{read_image, ColorEncoding};
use std::path::Path;
use std::process::{Command, Output};

fn facette(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_facette"))
        .args(args)
        .output()
        .expect("facette runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

const SCENE: &str = r#"<scene version="3.0.0">
    <default name="width" value="12"/>
    <default name="spp" value="2"/>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="$sampler"><integer name="sample_count" value="$spp"/></sampler>
        <film type="hdrfilm"><integer name="width" value="$width"/><integer name="height" value="6"/></film>
    </sensor>
    <shape type="sphere"><bsdf type="roughplastic"><float name="alpha" value="0.3"/></bsdf></shape>
    <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
</scene>
"#;

fn scene(dir: &Path) -> String {
    let p = dir.join("scene.xml");
    std::fs::write(&p, SCENE).unwrap();
    p.to_str().unwrap().to_string()
}

#[test]
fn render_reads_mitsuba_xml_and_takes_defines() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene(dir.path());
    let out = dir.path().join("out.exr");
    let o = facette(&[
        "render",
        &scene,
        "-o",
        out.to_str().unwrap(),
        "-D",
        "width=20",
        "--define",
        "sampler=independent",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
    let img = read_image(&out, ColorEncoding::Linear).unwrap();
    assert_eq!(
        (img.width(), img.height()),
        (20, 6),
        "-D width=20 overrides the default"
    );
    assert!(img
        .data()
        .iter()
        .flatten()
        .all(|v| v.is_finite() && *v >= 0.0));
    assert!(stderr(&o).contains("(20×6, 2 spp)"), "{}", stderr(&o));
}

#[test]
fn render_prints_mitsuba_warnings_once_and_errors_with_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene(dir.path());
    let out = dir.path().join("out.png");
    let o = facette(&[
        "render",
        &scene,
        "-o",
        out.to_str().unwrap(),
        "-D",
        "sampler=multijitter",
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert_eq!(
        err.matches("warning: ").count(),
        1,
        "one warning for the sampler type: {err}"
    );
    assert!(err.contains("scene.xml:7: sampler `multijitter`"), "{err}");
    assert!(out.exists());

    // No value for $sampler: an error naming the line; nothing is written.
    let out2 = dir.path().join("none.exr");
    let o = facette(&["render", &scene, "-o", out2.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("scene.xml:7: undefined parameter `$sampler`"),
        "{}",
        stderr(&o)
    );
    assert!(!out2.exists());

    // A malformed -D, and -D on a TOML scene.
    let o = facette(&["render", &scene, "-D", "novalue"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("is not NAME=VALUE"), "{}", stderr(&o));
    let toml = dir.path().join("s.toml");
    std::fs::write(
        &toml,
        "[camera]\nposition = [0, 0, 1]\ntarget = [0, 0, 0]\n",
    )
    .unwrap();
    let o = facette(&[
        "render",
        toml.to_str().unwrap(),
        "-D",
        "a=1",
        "-o",
        out2.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("applies to Mitsuba XML scenes (.xml) only"),
        "{}",
        stderr(&o)
    );
}
