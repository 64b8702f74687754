//! Mitsuba 3 XML scenes that are wrong: malformed XML, unknown plugins and parameters,
//! missing files and bad values are errors naming the file and line; parameters that only
//! affect quality are warnings, given once.

use crate::common::*;

#[test]
fn malformed_xml_is_an_error_with_file_and_line() {
    let e = error("<scene version=\"3.0.0\">\n  <shape type=\"sphere\">\n</scene>\n");
    assert!(e.starts_with("scene.xml:3: malformed XML"), "{e}");
    let e = error("<scene>\n</scene>");
    assert!(
        e.starts_with("scene.xml:1:") && e.contains("`version`"),
        "{e}"
    );
    let e = error(&scene_xml(
        "  <shape type=\"sphere\">\n  <float name=\"radius\"/></shape>",
    ));
    assert!(
        e.contains("scene.xml:9") && e.contains("needs the attribute `value`"),
        "{e}"
    );
    let e = error(&scene_xml(
        "<shape type=\"sphere\">\n  <float name=\"radius\" value=\"1\">2</float></shape>",
    ));
    assert!(
        e.contains("scene.xml:9") && e.contains("unexpected text `2`"),
        "{e}"
    );
}

#[test]
fn unknown_plugins_and_parameters_name_themselves_and_list_what_is_supported() {
    let e = error(&scene_xml("\n<shape type=\"cylinder\"/>"));
    assert!(
        e.contains("scene.xml:9")
            && e.contains("unsupported shape `cylinder`; supported: obj, ply, sphere"),
        "{e}"
    );
    let e = error(&scene_xml(
        "<shape type=\"sphere\"><bsdf type=\"principled\"/></shape>",
    ));
    assert!(
        e.contains("unsupported BSDF `principled`; supported: diffuse, conductor")
            && e.contains("il"),
        "{e}"
    );
    let e = error(&scene_xml("<emitter type=\"sunsky\"/>"));
    assert!(
        e.contains("unsupported emitter `sunsky`; supported: area, point, spot"),
        "{e}"
    );
    let e = error(&scene_xml("<integrator type=\"volpath\"/>"));
    assert!(
        e.contains("unsupported integrator `volpath`; supported: path"),
        "{e}"
    );
    let e = error(&scene_xml("<medium type=\"homogeneous\"/>"));
    assert!(e.contains("<medium> is not supported"), "{e}");
    let e = error(&scene_xml(
        "<shape type=\"sphere\">\n  <bsdf type=\"diffuse\">\n    <rgb name=\"reflectanse\" value=\"0.5\"/>\n  </bsdf>\n</shape>",
    ));
    assert!(
        e.contains("scene.xml:10")
            && e.contains("unknown parameter `reflectanse`; supported: reflectance"),
        "{e}"
    );
    let e = error(&scene_xml(
        "<shape type=\"rectangle\"><float name=\"radius\" value=\"1\"/></shape>",
    ));
    assert!(
        e.contains("unknown parameter `radius`; supported: to_world, flip_normals"),
        "{e}"
    );
    let e = error(&scene_xml(
        "<shape type=\"sphere\"><bsdf type=\"il\"><float name=\"kdd\" value=\"1\"/></bsdf></shape>",
    ));
    assert!(
        e.contains("scene.xml:8") && e.contains("kdd") && e.contains("valid"),
        "{e}"
    );
    let e = error(&scene_xml("<shape type=\"sphere\"><bsdf type=\"conductor\"><string name=\"material\" value=\"Hg\"/></bsdf></shape>"));
    assert!(
        e.contains("preset `Hg` is not built into facette (built in: Au, Ag, Cu, Al, Cr, none)"),
        "{e}"
    );
    let e = error(&scene_xml("<shape type=\"sphere\"><bsdf type=\"dielectric\"><string name=\"int_ior\" value=\"glass\"/></bsdf></shape>"));
    assert!(
        e.contains("\"glass\" is not a known medium") && e.contains("bk7"),
        "{e}"
    );
    let e = error(&scene_xml(
        "<integrator type=\"path\"><boolean name=\"hide_emitters\" value=\"true\"/></integrator>",
    ));
    assert!(e.contains("hide_emitters"), "{e}");
}

#[test]
fn missing_files_are_errors_at_the_line_that_names_them() {
    let e = error(&scene_xml(
        "\n<shape type=\"obj\"><string name=\"filename\" value=\"nowhere.obj\"/></shape>",
    ));
    assert!(
        e.contains("scene.xml:9") && e.contains("\"nowhere.obj\": file not found"),
        "{e}"
    );
    let e = error(&scene_xml("<include filename=\"gone.xml\"/>"));
    assert!(
        e.contains("scene.xml:8") && e.contains("included file \"gone.xml\" not found"),
        "{e}"
    );
    let e = error(&scene_xml(
        "<emitter type=\"envmap\"><string name=\"filename\" value=\"sky.exr\"/></emitter>",
    ));
    assert!(e.contains("\"sky.exr\": file not found"), "{e}");
    // A file that exists but is not a mesh: the loader's message, at the shape.
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "bad.ply", "not a ply file\n");
    let e = load_in(
        dir.path(),
        &scene_xml("\n\n<shape type=\"ply\"><string name=\"filename\" value=\"bad.ply\"/></shape>"),
        &[],
    )
    .err()
    .expect("an error");
    assert!(e.contains("scene.xml:10") && e.contains("bad.ply"), "{e}");
    // Errors inside an included file name that file.
    write(
        dir.path(),
        "inc.xml",
        "<scene version=\"3.0.0\">\n\n  <bsdf type=\"velvet\"/>\n</scene>",
    );
    let e = load_in(
        dir.path(),
        &scene_xml("<include filename=\"inc.xml\"/>"),
        &[],
    )
    .err()
    .expect("an error");
    assert!(
        e.contains("inc.xml:3") && e.contains("unsupported BSDF `velvet`"),
        "{e}"
    );
}

#[test]
fn bad_values_are_errors_with_the_line() {
    let e = error(&scene_xml(
        "\n<shape type=\"sphere\"><float name=\"radius\" value=\"big\"/></shape>",
    ));
    assert!(
        e.contains("scene.xml:9") && e.contains("\"big\" is not a number"),
        "{e}"
    );
    let e = error(&scene_xml(
        "<shape type=\"sphere\"><float name=\"radius\" value=\"-1\"/></shape>",
    ));
    assert!(e.contains("scene.xml:8") && e.contains("radius"), "{e}");
    let e = error(&scene_xml(
        "<shape type=\"sphere\"><rgb name=\"radius\" value=\"1\"/></shape>",
    ));
    assert!(
        e.contains("`radius` must be a <float>, not an <rgb>"),
        "{e}"
    );
    let e = error(&scene_xml("<shape type=\"sphere\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"1 2\"/></bsdf></shape>"));
    assert!(e.contains("one or three numbers"), "{e}");
    let e = error(&scene_xml("<shape type=\"sphere\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"1.5\"/></bsdf></shape>"));
    assert!(
        e.contains("scene.xml:8") && e.contains("reflectance"),
        "{e}"
    );
    let e = error(&scene_xml(
        "<shape type=\"sphere\"><boolean name=\"flip_normals\" value=\"yes\"/></shape>",
    ));
    assert!(e.contains("must be true or false"), "{e}");
    let e = error(&scene_xml(
        "<shape type=\"sphere\" id=\"a\"/><shape type=\"sphere\" id=\"a\"/>",
    ));
    assert!(e.contains("duplicate id \"a\""), "{e}");
    let e = error(&scene_xml(
        "<shape type=\"sphere\"><ref id=\"nothing\"/></shape>",
    ));
    assert!(e.contains("no object has this id"), "{e}");
    let e = error("<scene version=\"3.0.0\"><shape type=\"sphere\"/></scene>");
    assert!(e.contains("no <sensor>"), "{e}");
    let e = error(&scene_xml(
        "<integrator type=\"path\"><integer name=\"max_depth\" value=\"0\"/></integrator>",
    ));
    assert!(e.contains("max_depth"), "{e}");
}

#[test]
fn quality_only_parameters_are_warnings_given_once() {
    let s = load(
        &scene_xml(
            r#"<shape type="sphere"><point name="center" x="0" y="0" z="4.995"/><float name="radius" value="0.001"/></shape>"#,
        )
        .replace("type=\"independent\"", "type=\"multijitter\"")
        .replace("</sensor>", "</sensor>\n<sensor type=\"perspective\"><sampler type=\"multijitter\"/></sensor>"),
    );
    let sampler: Vec<_> = s
        .warnings
        .iter()
        .filter(|w| w.contains("sampler `multijitter` is rendered with facette's `stratified`"))
        .collect();
    assert_eq!(sampler.len(), 1, "{:?}", s.warnings);
    assert_eq!(
        s.film.sampler,
        facette_render::sampler::SamplerKind::Stratified
    );
    assert!(
        s.warnings.iter().any(|w| w.contains("first <sensor>")),
        "{:?}",
        s.warnings
    );
    assert!(
        s.warnings.iter().any(|w| w.contains("near_clip")),
        "{:?}",
        s.warnings
    );
}
