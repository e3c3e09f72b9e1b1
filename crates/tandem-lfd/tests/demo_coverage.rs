//! A demonstration that does not reach the end of the task is refused
//! (`Error::TruncatedDemonstration`), and legitimate variation is not: the committed sanding
//! demonstrations, one of them 20 % faster or slower, and pauses of independent length
//! (docs/decisions.md, "A demonstration must reach the end of the task").

use tandem_lfd::{Demonstration, Error, FitParams, TaskModel};

fn sanding(i: usize) -> Demonstration {
    let path = format!(
        "{}/../../fixtures/sanding/demo_{i}.csv",
        env!("CARGO_MANIFEST_DIR")
    );
    Demonstration::from_csv_path(path, None).unwrap()
}

/// `d` with `samples` as its samples, labelled `name`.
fn with(d: &Demonstration, samples: Vec<f64>, name: &str) -> Demonstration {
    Demonstration::new(d.channel_names().to_vec(), samples, d.dt_s())
        .unwrap()
        .with_source(name)
}

/// The first `share` of `d`'s samples.
fn cut(d: &Demonstration, share: f64, name: &str) -> Demonstration {
    let n = (d.n_samples() as f64 * share) as usize;
    with(d, d.samples()[..n * d.n_channels()].to_vec(), name)
}

/// `d` played `factor` times as long (linear interpolation; quaternions renormalized by the
/// fit's own nlerp are close enough at this spacing).
fn stretched(d: &Demonstration, factor: f64, name: &str) -> Demonstration {
    let (n, m) = (d.n_samples(), d.n_channels());
    let n2 = ((n - 1) as f64 * factor) as usize + 1;
    let mut s = Vec::with_capacity(n2 * m);
    for j in 0..n2 {
        let pos = (j as f64 / factor).min((n - 1) as f64);
        let lo = pos.floor() as usize;
        let hi = (lo + 1).min(n - 1);
        let a = pos - lo as f64;
        s.extend((0..m).map(|c| d.sample(lo)[c] * (1.0 - a) + d.sample(hi)[c] * a));
    }
    with(d, s, name)
}

/// `d` holding still for `len` samples at share `at` of its samples.
fn paused(d: &Demonstration, at: f64, len: usize, name: &str) -> Demonstration {
    let m = d.n_channels();
    let k = (d.n_samples() as f64 * at) as usize;
    let mut s = d.samples()[..k * m].to_vec();
    for _ in 0..len {
        s.extend_from_slice(d.sample(k));
    }
    s.extend_from_slice(&d.samples()[k * m..]);
    with(d, s, name)
}

#[test]
fn the_sanding_demonstrations_and_legitimate_variation_are_accepted() {
    let demos: Vec<Demonstration> = (0..6).map(sanding).collect();
    let p = FitParams::default();
    TaskModel::fit(&demos, &p).unwrap();
    let three = &demos[..3];
    for variant in [
        stretched(&demos[3], 0.8, "faster.csv"),
        stretched(&demos[3], 1.2, "slower.csv"),
        paused(&demos[3], 0.5, 1500, "pause_mid.csv"),
        paused(&demos[3], 0.98, 1500, "pause_end.csv"),
    ] {
        let mut set = three.to_vec();
        set.push(variant);
        TaskModel::fit(&set, &p).unwrap();
    }
}

#[test]
fn a_demonstration_cut_off_at_55_or_80_percent_is_refused() {
    let demos: Vec<Demonstration> = (0..3).map(sanding).collect();
    let p = FitParams::default();
    for (share, name, lo, hi) in [
        (0.55, "cut55.csv", 50.0, 70.0),
        (0.8, "cut80.csv", 75.0, 90.0),
    ] {
        let mut set = demos.clone();
        set.push(cut(&sanding(3), share, name));
        let err = TaskModel::fit(&set, &p).unwrap_err();
        let Error::TruncatedDemonstration {
            ref file,
            ends_at_pct,
            ..
        } = err
        else {
            panic!("{name}: {err}");
        };
        assert_eq!(file, name);
        assert!(
            (lo..hi).contains(&ends_at_pct),
            "{name}: ends at {ends_at_pct} %"
        );
        assert!(
            err.to_string().contains("demonstrate the whole task again"),
            "{err}"
        );
    }
}
