//! Mistakes made by the course's own binary and in the course's reference images: an
//! independent program's pictures, diagnosed as goldray's are.

use super::*;

/// The course's own binary rendered the course's scenes edited the way one mistake changes them
/// (`tests/data/mit6837/faulty/make.sh`): an independent program's sampling, rounding and
/// quantisation, with a mistake goldray did not draw. Every image that loses points is diagnosed
/// as the mistake it was made with.
#[test]
fn the_course_binarys_mistakes_are_diagnosed() {
    let dir = fresh_dir("diagnose-course-binary");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let rubric = dir.join("rubric.toml");
    fs::create_dir_all(&dir).unwrap();
    let text = fs::read_to_string(course_rubric(&dir))
        .unwrap()
        .replace(&format!("size = [{SIZE}, {SIZE}]"), "size = [200, 200]");
    fs::write(&rubric, text).unwrap();
    let faulty = root.join("tests/data/mit6837/faulty");
    let submissions = dir.join("submissions");
    let mut handed_in = 0;
    for entry in fs::read_dir(&faulty).unwrap().flatten().filter(|e| e.path().is_dir()) {
        let folder = submissions.join(entry.file_name());
        fs::create_dir_all(&folder).unwrap();
        for file in fs::read_dir(entry.path()).unwrap().flatten() {
            fs::copy(file.path(), folder.join(file.file_name())).unwrap();
            handed_in += 1;
        }
    }
    let options = GradeOptions {
        out: dir.join("report"),
        cache: Some(dir.join("cache")),
        ..GradeOptions::default()
    };
    let report = grade_class(&rubric, &submissions, &options, &Silent).unwrap();
    let (mut lost, mut named, mut wrong) = (0, 0, Vec::new());
    for student in &report.students {
        for image in student.images.iter().filter(|i| goldray::grade::loses_points(i)) {
            lost += 1;
            let diagnosis = image.diagnosis.as_ref().unwrap();
            let ids: Vec<&str> = std::iter::once(diagnosis.id.as_str())
                .chain(diagnosis.alternatives.iter().map(String::as_str))
                .collect();
            println!(
                "{} {}: {} ({:?}) {}",
                student.name,
                image.file,
                diagnosis.faults.as_deref().unwrap_or("unexplained"),
                diagnosis.alternatives,
                image.explanation
            );
            if ids.contains(&student.name.as_str()) {
                named += 1;
            } else if diagnosis.id != UNEXPLAINED {
                wrong.push(format!("{} {}: {}", student.name, image.file, diagnosis.id));
            }
        }
    }
    println!("{named} of {lost} images that lost points named ({handed_in} handed in)");
    assert!(wrong.is_empty(), "{wrong:?}");
    assert!(lost >= 14, "only {lost} of {handed_in} images lost points");
    assert_eq!(named, lost, "every image that lost points is named");
}

/// The course's reference images (800×800, made by the course's binary) as a correct submission
/// get no diagnosis; with a mistake of the PNG writing applied to their 8-bit codes (all a program
/// that quantised first and then made the mistake could have written) each is diagnosed as it.
#[test]
fn the_course_references_with_output_mistakes_are_diagnosed() {
    let dir = fresh_dir("diagnose-references");
    fs::create_dir_all(&dir).unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut rubric = "[defaults]\nthreshold = 8\npass_fraction = 0.01\npartial_fraction = 0.05\npass_flip = 0.1\npartial_flip = 0.2\n".to_owned();
    for (n, scene, range) in [
        ("01", "scene01_plane", "8, 18"),
        ("02", "scene02_cube", "8, 18"),
        ("05", "scene05_bunny_200", "0.8, 1.0"),
    ] {
        let scene = root.join(format!("cases/mit6837/{scene}.txt"));
        rubric += &format!(
            "[render.s{n}]\nscene = {scene:?}\nsize = [800, 800]\n[image.\"a{n}.png\"]\nrender = \"s{n}\"\n\
             [image.\"a{n}n.png\"]\nrender = \"s{n}\"\noutput = \"normals\"\n\
             [image.\"a{n}d.png\"]\nrender = \"s{n}\"\noutput = \"depth\"\ndepth = [{range}]\n"
        );
    }
    let rubric_path = dir.join("rubric.toml");
    fs::write(&rubric_path, rubric).unwrap();
    let reference = |file: &str| read_png(&root.join("tests/data/mit6837").join(file)).unwrap();
    let submissions = dir.join("submissions");
    let correct = submissions.join("reference");
    fs::create_dir_all(&correct).unwrap();
    for n in ["01", "02", "05"] {
        for suffix in ["", "n", "d"] {
            let file = format!("a{n}{suffix}.png");
            fs::copy(root.join("tests/data/mit6837").join(&file), correct.join(&file)).unwrap();
        }
    }
    // A linear value within its 8-bit code, for curves applied after quantising.
    let value = |code: u8| {
        if code == 0 {
            0.0
        } else {
            (f64::from(code) + 0.5) / 255.0
        }
    };
    let curve = |picture: &RgbImage, f: &dyn Fn(f64) -> f64| {
        let mut out = picture.clone();
        out.pixels_mut()
            .for_each(|p| p.0 = p.0.map(|c| (f(value(c)).clamp(0.0, 1.0) * 255.0) as u8));
        out
    };
    let srgb = |c: f64| {
        if c <= 0.003_130_8 {
            12.92 * c
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        }
    };
    let miss = |normals: &RgbImage, x: u32, y: u32| normals.get_pixel(x, y).0 == [127; 3];
    let mistakes: Vec<(&str, &str, RgbImage)> = vec![
        (
            "a01.png",
            "gamma-applied",
            curve(&reference("a01.png"), &|c| c.powf(1.0 / 2.2)),
        ),
        (
            "a02.png",
            "gamma-applied",
            curve(&reference("a02.png"), &|c| c.powf(1.0 / 1.8)),
        ),
        ("a05.png", "gamma-applied", curve(&reference("a05.png"), &srgb)),
        (
            "a01n.png",
            "normals-not-remapped",
            curve(&reference("a01n.png"), &|c| 2.0 * c - 1.0),
        ),
        ("a02n.png", "pixel-mapping", reference("a02n.png").flipped_vertically()),
        (
            "a05n.png",
            "pixel-mapping",
            reference("a05n.png").flipped_horizontally(),
        ),
        ("a02d.png", "depth-inverted", {
            let (depth, normals) = (reference("a02d.png"), reference("a02n.png"));
            RgbImage::from_fn(800, 800, |x, y| {
                if miss(&normals, x, y) {
                    Rgb([0; 3])
                } else {
                    Rgb(depth.get_pixel(x, y).0.map(|c| 254 - c.min(254)))
                }
            })
        }),
        ("a01d.png", "depth-miss-white", {
            let (depth, normals) = (reference("a01d.png"), reference("a01n.png"));
            RgbImage::from_fn(800, 800, |x, y| {
                if miss(&normals, x, y) {
                    Rgb([255; 3])
                } else {
                    *depth.get_pixel(x, y)
                }
            })
        }),
        ("a05d.png", "pixel-mapping", reference("a05d.png").flipped_vertically()),
    ];
    let faulty = submissions.join("outputs");
    fs::create_dir_all(&faulty).unwrap();
    for (file, _, picture) in &mistakes {
        fs::write(faulty.join(file), encode_png(picture).unwrap()).unwrap();
    }
    let options = GradeOptions {
        out: dir.join("report"),
        cache: Some(dir.join("cache")),
        ..GradeOptions::default()
    };
    let report = grade_class(&rubric_path, &submissions, &options, &Silent).unwrap();
    let by_name = |name: &str| report.students.iter().find(|s| s.name == name).unwrap();
    for image in &by_name("reference").images {
        assert!(
            image.diagnosis.is_none() && image.points == image.max_points,
            "{}: {}",
            image.file,
            image.explanation
        );
    }
    for (file, id, _) in &mistakes {
        let image = by_name("outputs").images.iter().find(|i| i.file == *file).unwrap();
        let diagnosis = image
            .diagnosis
            .as_ref()
            .unwrap_or_else(|| panic!("{file}: {}", image.explanation));
        println!(
            "{file}: {} ({:?})",
            diagnosis.faults.as_deref().unwrap_or("unexplained"),
            diagnosis.alternatives
        );
        assert_eq!(diagnosis.id, *id, "{file}: {}", image.explanation);
    }
}
