//! `subd render` and the README pictures.

use super::*;

/// The pixels of an 8-bit RGB PNG, with its width and height.
fn read_png(path: &Path) -> (usize, usize, Vec<[u8; 3]>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    let pixels = buf[..info.buffer_size()]
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    (info.width as usize, info.height as usize, pixels)
}

#[test]
fn render_draws_a_limit_sphere_as_the_expected_disc() {
    let s = Scratch::new("render");
    let ico = meshes().join("loop_icosahedron.obj");
    let picture = s.0.join("ico.png");
    let (code, _, err) = subd(&[
        "render",
        ico.to_str().unwrap(),
        picture.to_str().unwrap(),
        "--limit",
        "--levels",
        "4",
        "--size",
        "240x200",
        "--view",
        "0,0",
    ]);
    assert_eq!(code, 0, "{err}");
    // The limit surface's extent, from `subd refine --limit` at the same level: the picture
    // frames the bounding sphere about the bounding box's centre into 45% of the shorter side
    // (90 pixels); looking down −z, the silhouette is the surface's extent in x and y.
    let samples = s.0.join("ico-limit.obj");
    let (code, _, err) = subd(&[
        "refine",
        "--scheme",
        "loop",
        "--levels",
        "4",
        "--limit",
        ico.to_str().unwrap(),
        samples.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let p = subd_io::read_mesh(&samples, &subd_io::ReadOptions::default())
        .unwrap()
        .mesh
        .positions;
    let (lo, hi) = p.iter().fold(
        (
            subd_mesh::DVec3::splat(f64::MAX),
            subd_mesh::DVec3::splat(f64::MIN),
        ),
        |(l, h), q| (l.min(*q), h.max(*q)),
    );
    let c = (lo + hi) / 2.0;
    let radius = p.iter().map(|q| q.distance(c)).fold(0.0, f64::max);
    let inner = p.iter().map(|q| q.distance(c)).fold(f64::MAX, f64::min);
    let scale = 90.0 / radius;
    assert!(inner / radius > 0.97, "sphere-like: {inner} .. {radius}");
    let (w, h, pixels) = read_png(&picture);
    assert_eq!((w, h), (240, 200));
    let background = pixels[0];
    let (cx, cy) = (120.0 + scale * -c.x, 100.0 - scale * c.y);
    let (mut inside, mut covered) = (0usize, 0usize);
    for y in 0..h {
        for x in 0..w {
            let d = ((x as f64 + 0.5 - cx).powi(2) + (y as f64 + 0.5 - cy).powi(2)).sqrt();
            let px = pixels[y * w + x];
            if d < scale * inner - 1.5 {
                assert_ne!(
                    px, background,
                    "pixel ({x}, {y}) inside the disc is background"
                );
                inside += 1;
            }
            if d > scale * radius + 1.5 {
                assert_eq!(px, background, "pixel ({x}, {y}) outside the disc is drawn");
            }
            covered += usize::from(px != background);
        }
    }
    let r_mid = scale * (inner + radius) / 2.0;
    let expected = std::f64::consts::PI * r_mid * r_mid;
    assert!(inside > 20_000, "{inside}");
    assert!(
        (covered as f64 / expected - 1.0).abs() < 0.04,
        "{covered} pixels, expected about {expected:.0}"
    );
    // Lit from the upper left: the upper-left quadrant is brighter than the lower right.
    let luma = |x: usize, y: usize| pixels[y * w + x].iter().map(|&v| u32::from(v)).sum::<u32>();
    assert!(luma(95, 75) > luma(145, 125));

    // The cage is drawn over the surface in its own colour; bad requests leave no file.
    let caged = s.0.join("caged.png");
    let (code, _, err) = subd(&[
        "render",
        ico.to_str().unwrap(),
        caged.to_str().unwrap(),
        "--cage",
        "--scheme",
        "loop",
    ]);
    assert_eq!(code, 0, "{err}");
    let (_, _, pixels) = read_png(&caged);
    assert!(pixels.contains(&[214, 96, 20]), "cage colour present");
    for (args, expect) in [
        (vec!["--size", "0x10"], "a side is 1 to"),
        (vec!["--levels", "2"], "--levels needs --scheme or --limit"),
        (vec!["--view", "north"], "AZIMUTH,ELEVATION"),
    ] {
        let bad = s.0.join("bad.png");
        let mut a = vec!["render", ico.to_str().unwrap(), bad.to_str().unwrap()];
        a.extend(args);
        let (code, _, err) = subd(&a);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(expect), "{err}");
        assert!(!bad.exists());
    }
    let (code, _, err) = subd(&[
        "render",
        ico.to_str().unwrap(),
        s.0.join("x.jpg").to_str().unwrap(),
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("expected .png"), "{err}");
}

#[test]
fn the_readme_pictures_come_from_docs_pictures_sh() {
    let s = Scratch::new("pictures");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let status = Command::new("bash")
        .arg("docs/pictures.sh")
        .current_dir(&root)
        .env("SUBD", env!("CARGO_BIN_EXE_subd"))
        .env("OUT", &s.0)
        .status()
        .expect("run bash");
    assert!(status.success());
    for name in [
        "torus_creased.png",
        "pia_targets.png",
        "adaptive_levels.png",
    ] {
        let (w, h, made) = read_png(&s.0.join(name));
        let (cw, ch, committed) = read_png(&root.join("docs").join(name));
        assert_eq!((w, h), (cw, ch), "{name}");
        let differing = made.iter().zip(&committed).filter(|(a, b)| a != b).count();
        assert!(
            differing * 100 < made.len(),
            "{name}: {differing} of {} pixels differ from the committed picture",
            made.len()
        );
    }
}
