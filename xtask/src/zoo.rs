//! `cargo xtask zoo`: the whole loop measured on every family of the task zoo
//! (`tandem_zoo::eval`; issue 38, docs/zoo.md).
//!
//! Per family and seed: the fit with the defaults (and the family's hold rules), then for every
//! robot count and cell a short learning run with the simulated operator who follows the
//! family's truth. Writes `<out>/zoo.json` (git revision, parameters, every fit and run, the
//! per-family rows), `<out>/zoo.md` (the tables) and `<out>/zoo.svg`/`.png` (per family: final
//! `T_total` over its bound, and high confidence against the truth). With `--docs` the tables
//! replace the section of docs/zoo.md for the seed set (`select` or `held-out`), and the
//! held-out figure is copied to docs/figures/zoo.png. With `--check` it fails, naming every
//! breach, when a run has a backward step or an overlap, or a family's mean breaks the gap or
//! high-confidence limits (`tandem_zoo::eval::Thresholds::CI`, overridable by flags). With
//! `--from a.json,b.json` it renders and checks saved reports (batches of families run
//! separately) instead of running.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, anyhow, bail};
use indicatif::{ProgressBar, ProgressStyle};
use plotters::prelude::*;
use serde::{Deserialize, Serialize};
use tandem::sim::study::{Cell, StudyInputs};
use tandem_plot::{FONT_FAMILY, GROUND_TRUTH, HIGH_CONFIDENCE, ROBOT_LC_N};
use tandem_zoo::eval::{
    EvalParams, FamilyRow, FitRow, SANDING, Step, Thresholds, ZooReport, check, evaluate,
    export_alignments, family_rows, fit_rows, prepare_sanding,
};

use crate::workspace_root;

/// Flags of `cargo xtask zoo`.
#[derive(clap::Args, Debug)]
pub(crate) struct ZooArgs {
    /// Seeds of every family: `select` (the selection seeds, 0..8, on which defaults may be
    /// chosen), `held-out` (1000..1008, never tuned on) or a comma-separated list.
    #[arg(long, default_value = "held-out")]
    seeds: String,
    /// Families (comma-separated; default: every family). `sanding` is the sanding fixture
    /// (fixtures/sanding, with the study's hold rules from fixtures/study.toml), run by the
    /// same loop beside the zoo (one seed: the fixture).
    #[arg(long, value_delimiter = ',')]
    families: Vec<String>,
    /// Robot counts N (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "2,3,4")]
    robots: Vec<usize>,
    /// Cells: rounds, continuous or both.
    #[arg(long, default_value = "both", value_parser = ["rounds", "continuous", "both"])]
    cell: String,
    /// Learning rounds per run (continuous: re-plans, one per N tasks).
    #[arg(long, default_value_t = tandem_zoo::eval::DEFAULT_ROUNDS)]
    rounds: usize,
    /// Skip the reference-choice spread (one more fit per demonstration, and the medoid).
    #[arg(long)]
    no_spread: bool,
    /// Fit with this rate term instead of the default (`absolute`, `relative`,
    /// `relative:opening=N,window=M`): a variant to compare.
    #[arg(long, value_name = "FORM")]
    rate_term: Option<tandem::lfd::RateTerm>,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long)]
    threads: Option<usize>,
    /// Output folder (created if missing). Default: results/zoo/ in the workspace.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Also write the tables into docs/zoo.md (the section of this seed set) and, for the
    /// held-out seeds, the figure to docs/figures/zoo.png.
    #[arg(long)]
    docs: bool,
    /// Render (and check) saved reports instead of running: zoo.json files of earlier runs,
    /// comma-separated (e.g. batches of families); their runs are put together.
    #[arg(long, value_delimiter = ',')]
    from: Vec<PathBuf>,
    /// Fail (exit non-zero, naming each breach) on a backward step, an overlap, or a family
    /// whose mean breaks the limits below.
    #[arg(long)]
    check: bool,
    /// Limit of a family's mean `T_total / bound − 1` with two robots (percent).
    #[arg(long, default_value_t = Thresholds::CI.max_gap_pct_n2)]
    max_gap_n2: f64,
    /// The same with three robots (percent).
    #[arg(long, default_value_t = Thresholds::CI.max_gap_pct_n3)]
    max_gap_n3: f64,
    /// The same with four or more robots (percent).
    #[arg(long, default_value_t = Thresholds::CI.max_gap_pct_n4)]
    max_gap_n4: f64,
    /// Limit of a family's mean |high confidence − truth| (percentage points).
    #[arg(long, default_value_t = Thresholds::CI.max_high_vs_truth_pp)]
    max_hc_pp: f64,
    /// Instead of running: generate and fit the families at the seeds and write, per task,
    /// the demonstrations as the fit's alignment sees them (weighted), their true progress and
    /// the fit's warps into `DIR/<family>/<seed>/`, for `bench/peers/zoo_gdtw.py`.
    #[arg(long, value_name = "DIR")]
    export_alignments: Option<PathBuf>,
    /// A peer aligner's errors against the known warps (the JSON files
    /// `bench/peers/zoo_gdtw.py` writes), shown beside the fit's in the fit table.
    #[arg(long, value_delimiter = ',', value_name = "JSON")]
    peer_warps: Vec<PathBuf>,
}

/// A peer aligner's error against the known warps on one task (written by
/// `bench/peers/zoo_gdtw.py`; the same definition as `tandem_zoo::eval::WarpError`).
#[derive(Clone, Debug, Serialize, Deserialize)]
struct PeerTask {
    /// The family.
    family: String,
    /// The seed.
    seed: u64,
    /// Demonstrations scored.
    pairs: usize,
    /// Mean error, reference samples.
    mean_samples: f64,
    /// Largest error, reference samples.
    max_samples: f64,
    /// The peer's wall time over the task's pairs, seconds.
    wall_s: f64,
}

/// A peer aligner's errors: what `bench/peers/zoo_gdtw.py` writes.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct PeerWarps {
    /// The tool and version (e.g. `gdtw 1.2.1`).
    tool: String,
    /// Its setting (e.g. `default`).
    setting: String,
    /// Per task.
    tasks: Vec<PeerTask>,
}

/// What `zoo.json` holds.
#[derive(Serialize, Deserialize)]
struct ZooFile {
    /// `git describe --always --dirty` of the workspace, or "unknown".
    git_revision: String,
    /// The seed set's name (`select`, `held-out`, or `custom`).
    seed_set: String,
    /// Per family, `N` and cell: means over seeds.
    family_rows: Vec<FamilyRow>,
    /// Per family: the fits, means over seeds.
    fit_rows: Vec<FitRow>,
    /// Everything: parameters, every fit and run.
    report: ZooReport,
    /// Peer aligners' errors against the known warps (`--peer-warps`), if given.
    #[serde(default)]
    peer_warps: Vec<PeerWarps>,
}

/// The seeds of `--seeds` and the seed set's name.
fn seeds(arg: &str) -> anyhow::Result<(Vec<u64>, String)> {
    match arg {
        "select" | "selection" => Ok((tandem_zoo::SELECTION_SEEDS.collect(), "select".into())),
        "held-out" | "heldout" => Ok((tandem_zoo::HELD_OUT_SEEDS.collect(), "held-out".into())),
        list => {
            let seeds = list
                .split(',')
                .map(|s| s.trim().parse::<u64>())
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| {
                    anyhow!(
                        "--seeds {list}: {e}; give `select`, `held-out` or seeds like 1000,1001"
                    )
                })?;
            let held_out = seeds.iter().all(|s| tandem_zoo::HELD_OUT_SEEDS.contains(s));
            Ok((seeds, if held_out { "held-out" } else { "custom" }.into()))
        }
    }
}

/// `cargo xtask zoo`.
pub(crate) fn run(args: &ZooArgs) -> anyhow::Result<()> {
    let root = workspace_root();
    let out = args.out.clone().unwrap_or_else(|| root.join("results/zoo"));
    let limits = Thresholds {
        max_gap_pct_n2: args.max_gap_n2,
        max_gap_pct_n3: args.max_gap_n3,
        max_gap_pct_n4: args.max_gap_n4,
        max_high_vs_truth_pp: args.max_hc_pp,
        ..Thresholds::CI
    };
    let wall = Instant::now();
    if let Some(dir) = &args.export_alignments {
        return export(args, dir);
    }
    let (report, seed_set, mut peer_warps) = if args.from.is_empty() {
        let (report, set) = run_zoo(args)?;
        (report, set, Vec::new())
    } else {
        merge(&args.from)?
    };
    for path in &args.peer_warps {
        let text =
            std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
        let peer: PeerWarps = serde_json::from_str(&text).with_context(|| {
            format!(
                "{}: not a peer-warp file of bench/peers/zoo_gdtw.py",
                path.display()
            )
        })?;
        add_peer(&mut peer_warps, peer);
    }
    let file = ZooFile {
        git_revision: crate::study::git_revision(&root),
        seed_set: seed_set.clone(),
        family_rows: family_rows(&report),
        fit_rows: fit_rows(&report),
        report,
        peer_warps,
    };
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let json = out.join("zoo.json");
    std::fs::write(&json, serde_json::to_string(&file)? + "\n")
        .with_context(|| format!("writing {}", json.display()))?;
    let tables = markdown(&file);
    let md = out.join("zoo.md");
    std::fs::write(&md, &tables).with_context(|| format!("writing {}", md.display()))?;
    draw(&file, &out.join("zoo.svg"), &out.join("zoo.png"))?;
    println!("{tables}");
    println!(
        "wrote {}, {} and zoo.svg/.png ({:.0} s)",
        json.display(),
        md.display(),
        wall.elapsed().as_secs_f64()
    );
    if args.docs {
        write_docs(&root, &file, &tables, &out)?;
    }
    if args.check {
        let breaches = check(&file.report, &limits);
        if !breaches.is_empty() {
            for b in &breaches {
                eprintln!("zoo check: {}: {}", b.at, b.what);
            }
            bail!(
                "{} breaches of the zoo's limits (tandem_zoo::eval::Thresholds; flags --max-gap-n2, \
                 --max-gap-n3, --max-gap-n4, --max-hc-pp)",
                breaches.len()
            );
        }
        println!("zoo check: every limit holds ({limits:?})");
    }
    Ok(())
}

/// Adds `peer`'s tasks to the entry of `peers` with the same tool and setting (one column
/// per setting however many files it came in; a task given twice counts once, the later
/// file's), or appends it.
fn add_peer(peers: &mut Vec<PeerWarps>, peer: PeerWarps) {
    match peers
        .iter_mut()
        .find(|p| p.tool == peer.tool && p.setting == peer.setting)
    {
        Some(p) => {
            for t in peer.tasks {
                p.tasks
                    .retain(|u| !(u.family == t.family && u.seed == t.seed));
                p.tasks.push(t);
            }
        }
        None => peers.push(peer),
    }
}

/// The families of `--families` (every family when none is given; `sanding` left out).
fn zoo_families(args: &ZooArgs) -> anyhow::Result<Vec<&'static tandem_zoo::Family>> {
    if args.families.is_empty() {
        return Ok(tandem_zoo::families().iter().collect());
    }
    args.families
        .iter()
        .filter(|f| *f != SANDING)
        .map(|f| tandem_zoo::family(f).map_err(|e| anyhow!("--families: {e} (or `{SANDING}`)")))
        .collect()
}

/// `--export-alignments DIR`: the families' demonstrations, true progress and fitted warps
/// for a peer aligner.
fn export(args: &ZooArgs, dir: &Path) -> anyhow::Result<()> {
    let (seeds, _) = seeds(&args.seeds)?;
    let families = zoo_families(args)?;
    if families.is_empty() {
        bail!("--export-alignments: the sanding fixture has no known warps; name zoo families");
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()
        .context("building the thread pool")?;
    let planner = EvalParams::default().planner;
    let metas = pool.install(|| export_alignments(&families, &seeds, &planner, dir))?;
    for m in &metas {
        println!(
            "{} seed {}: {} demonstrations, reference {}; fit's warp error {:.2} mean, {:.1} max \
             (reference samples)",
            m.family,
            m.seed,
            m.n_demos,
            m.reference_idx,
            m.tandem.mean_samples,
            m.tandem.max_samples
        );
    }
    println!(
        "wrote {} tasks into {}; run bench/peers/zoo_gdtw.py on it",
        metas.len(),
        dir.display()
    );
    Ok(())
}

/// Runs the evaluation the flags ask for, with a progress bar.
fn run_zoo(args: &ZooArgs) -> anyhow::Result<(ZooReport, String)> {
    let (seeds, mut seed_set) = seeds(&args.seeds)?;
    let sanding = args.families.iter().any(|f| f == SANDING);
    let families = zoo_families(args)?;
    if sanding && families.is_empty() {
        seed_set = SANDING.into();
    }
    let cells = match args.cell.as_str() {
        "rounds" => vec![Cell::Rounds],
        "continuous" => vec![Cell::Continuous],
        _ => vec![Cell::Rounds, Cell::Continuous],
    };
    let mut params = EvalParams {
        seeds,
        robots: args.robots.clone(),
        cells,
        rounds: args.rounds,
        reference_spread: !args.no_spread,
        ..EvalParams::default()
    };
    if let Some(rate_term) = args.rate_term {
        params.planner.fit.rate_term = rate_term;
    }
    params.validate().map_err(|e| anyhow!("{e}"))?;
    let extra = if sanding {
        let root = workspace_root();
        let inputs = StudyInputs::from_dir(&root.join("fixtures/sanding"))?;
        let (config, _) = crate::study::read_config(None)?;
        let holds: Vec<String> = config
            .planner
            .holds
            .rules
            .iter()
            .map(|r| r.to_string())
            .collect();
        vec![prepare_sanding(&inputs, &holds, &params.planner)?]
    } else {
        Vec::new()
    };
    let bar = ProgressBar::new(tandem_zoo::eval::steps(
        &params,
        families.len(),
        extra.len(),
    ));
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} zoo [{elapsed_precise}] {bar:40} {pos}/{len} fits and rounds (eta {eta})",
        )
        .map_err(|e| anyhow!("progress bar template: {e}"))?,
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()
        .context("building the thread pool")?;
    let report = pool.install(|| evaluate(&families, extra, &params, &|_: Step| bar.inc(1)))?;
    bar.finish_and_clear();
    Ok((report, seed_set))
}

/// Reads saved reports and puts their fits and runs together (the first one's parameters,
/// with every seed, robot count and cell of any).
fn merge(paths: &[PathBuf]) -> anyhow::Result<(ZooReport, String, Vec<PeerWarps>)> {
    let mut merged: Option<(ZooReport, String)> = None;
    let mut peers: Vec<PeerWarps> = Vec::new();
    for path in paths {
        let text =
            std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
        let file: ZooFile = serde_json::from_str(&text)
            .with_context(|| format!("{}: not a zoo.json of this version", path.display()))?;
        for peer in file.peer_warps {
            add_peer(&mut peers, peer);
        }
        match &mut merged {
            None => merged = Some((file.report, file.seed_set)),
            Some((m, set)) => {
                if *set != file.seed_set {
                    bail!(
                        "{}: seed set {} differs from {} of the first file",
                        path.display(),
                        file.seed_set,
                        set
                    );
                }
                for f in file.report.families {
                    if !m.families.contains(&f) {
                        m.families.push(f);
                    }
                }
                // A task fitted in two files (its rounds and its continuous cell run apart)
                // counts once, with its reference-choice spread where one file measured it.
                for fit in file.report.fits {
                    match m
                        .fits
                        .iter_mut()
                        .find(|f| f.family == fit.family && f.seed == fit.seed)
                    {
                        Some(f) if f.spread.is_none() => *f = fit,
                        Some(_) => {}
                        None => m.fits.push(fit),
                    }
                }
                m.runs.extend(file.report.runs);
            }
        }
    }
    let (mut report, set) = merged.context("--from needs at least one file")?;
    // Family order of the zoo, then seed, robots, cell.
    let rank = |f: &str| {
        tandem_zoo::families()
            .iter()
            .position(|g| g.name == f)
            .unwrap_or(usize::MAX)
    };
    report.families.sort_by_key(|f| rank(f));
    report.fits.sort_by_key(|f| (rank(&f.family), f.seed));
    let cell = |c: Cell| usize::from(c == Cell::Continuous);
    report
        .runs
        .sort_by_key(|r| (rank(&r.family), r.seed, r.robots, cell(r.cell)));
    Ok((report, set, peers))
}

/// A number with `d` decimals, or "—" when it is not finite.
fn num(v: f64, d: usize) -> String {
    if v.is_finite() {
        format!("{v:.d$}")
    } else {
        "—".into()
    }
}

fn cell_name(c: Cell) -> &'static str {
    match c {
        Cell::Rounds => "rounds",
        Cell::Continuous => "continuous",
    }
}

/// The Markdown tables of a report.
fn markdown(file: &ZooFile) -> String {
    let p = &file.report.params;
    let tasks = if file.seed_set == SANDING {
        "The sanding fixture (`fixtures/sanding`, the study's hold rules; one task)".to_string()
    } else {
        format!(
            "Seeds `{}` ({})",
            file.seed_set,
            p.seeds
                .iter()
                .map(u64::to_string)
                .collect::<Vec<_>>()
                .join(",")
        )
    };
    let mut s = format!(
        "{tasks}, {} rounds per run (continuous: re-plans after N tasks each), git `{}`.\n\
         Means over seeds; for a continuous cell `T_total` is the plan's period `P` (N tasks) and \
         the bound its `lower_bound_s`.\n\n",
        p.rounds, file.git_revision
    );
    s.push_str(
        "| family | N | cell | T_total (s) | bound (s) | gap % (max) | T/serial | HC % | truth % | \
         HC − truth pp (max) | falsely trusted: vary / agree | first overlap (round) | \
         max increase s (ticks) | realized / planned | tasks/h planned → realized | backward | \
         overlap |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in &file.family_rows {
        let overlap = match (r.cell, r.first_overlap_round) {
            (Cell::Continuous, _) => "—".to_string(),
            (_, Some(k)) if r.never_overlapped == 0 => num(k, 1),
            (_, Some(k)) => format!("{} ({} never)", num(k, 1), r.never_overlapped),
            (_, None) => "never".into(),
        };
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} ({}) | {} | {} | {} | {} ({}) | {} / {} | {} | {} ({}) | {} | {} → {} | {} | {} |\n",
            r.family,
            r.robots,
            cell_name(r.cell),
            num(r.t_total_s, 2),
            num(r.bound_s, 2),
            num(r.gap_pct, 1),
            num(r.gap_max_pct, 1),
            num(r.over_serial, 3),
            num(r.high_pct, 1),
            num(r.truth_pct, 1),
            num(r.high_minus_truth_pp, 1),
            num(r.high_minus_truth_max_pp, 1),
            num(r.falsely_trusted, 1),
            num(r.falsely_trusted_agreeing, 1),
            overlap,
            num(r.max_increase_s.max(0.0), 2),
            num(r.max_increase_ticks.max(0.0), 0),
            num(r.realized_over_planned, 3),
            num(r.planned_per_h, 1),
            num(r.realized_per_h, 1),
            r.backward_steps,
            r.overlap_ticks + r.faults,
        ));
    }
    s.push_str(
        "\nRealized against planned, by cause (percent of planned time, mean over seeds; rounds: \
         every round's realized − planned `T_total`; continuous: the steady window's tasks \
         against the plan's period, where `holds` are the waits at gates for the operator's \
         token). The causes add up to the first column (`PlanGap`, docs/decisions.md, \
         \"Plans that say how optimistic they are\"); needed but unsupervised: samples run at \
         high confidence where the truth needed the operator.\n\n\
         | family | N | cell | over plan % | corrections | holds | strategy | grid | faults | \
         critical path | needed but unsupervised |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in &file.family_rows {
        let [c, h, st, g, f, cp] = r.cause_pct;
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            r.family,
            r.robots,
            cell_name(r.cell),
            num(r.over_plan_pct, 1),
            num(c, 1),
            num(h, 1),
            num(st, 1),
            num(g, 1),
            num(f, 1),
            num(cp, 1),
            num(r.needed_unsupervised, 1),
        ));
    }
    let fated = |r: &&FamilyRow| {
        let f = r.by_fate;
        f.valid.count + f.repaired.count + f.invalid.count > 0
    };
    if file.family_rows.iter().any(|r| fated(&r)) {
        s.push_str(
            "\nRound-to-round changes of `T_total` by what became of the previous schedule in the \
             re-schedule that made the later plan (`Outcome::previous`; rounds; re-schedules \
             counted over every seed, the largest increase of one, s, ≤ 0 when none \
             increased). `valid`: the old schedule still passes every constraint on the updated \
             model, so the re-schedule is never longer and an increase would be the \
             scheduler's; `repaired`: the model update broke it (a low-confidence sample's mean \
             gradient moved, Eq. 20 constraint 4) and its re-timing passes, so the re-schedule \
             is never longer than the re-timing and an increase is what the update and the \
             re-timing cost; `invalid`: neither passes, nothing bounds the re-schedule.\n\n\
             | family | N | re-schedules: valid / repaired / invalid | max increase s: valid | \
             repaired | invalid |\n|---|---|---|---|---|---|\n",
        );
        for r in file.family_rows.iter().filter(fated) {
            let f = r.by_fate;
            let inc = |c: tandem_zoo::eval::FateCount| {
                c.max_increase_s
                    .map_or_else(|| "—".to_string(), |x| num(x, 3))
            };
            s.push_str(&format!(
                "| {} | {} | {} / {} / {} | {} | {} | {} |\n",
                r.family,
                r.robots,
                f.valid.count,
                f.repaired.count,
                f.invalid.count,
                inc(f.valid),
                inc(f.repaired),
                inc(f.invalid),
            ));
        }
    }
    if file.family_rows.iter().any(|r| r.gap_split_pct.is_some()) {
        s.push_str(
            "\nWhere the gap goes (rounds; percent of the bound, mean over seeds; \
             `Outcome::gap_split`): `search` is what the margin-free search left open (the best \
             schedule it found without margins above the bound; 0 when the bound is its proven \
             optimum), `margins` the rest, what the worst-case margins between the robots' \
             low-confidence stretches and the waits of release rules cost, plus what the \
             scheduler did not find. They add up to the gap. `of it unavoidable` is the part \
             of `margins` that no valid schedule avoids: every switch between the two robots' \
             low-confidence runs charged the margin check's least step and the drag lead \
             it must see there (`tandem_schedule::drag_charged_bound`; two robots without \
             hold points; the \
             seeds measured in brackets, — for none).\n\n\
             | family | N | gap % | search | margins | of it unavoidable | seeds with a proven bound |\n\
             |---|---|---|---|---|---|---|\n",
        );
        for r in &file.family_rows {
            if let Some((search, margins)) = r.gap_split_pct {
                let unavoidable = r
                    .unavoidable_pct
                    .map_or_else(|| "—".to_string(), |(u, n)| format!("{} ({n})", num(u, 1)));
                s.push_str(&format!(
                    "| {} | {} | {} | {} | {} | {} | {} of {} |\n",
                    r.family,
                    r.robots,
                    num(r.gap_pct, 1),
                    num(search, 1),
                    num(margins, 1),
                    unavoidable,
                    r.bound_proven,
                    r.seeds,
                ));
            }
        }
    }
    s.push_str(
        "\nThe fit alone (defaults, before any round): high confidence of the prior against the \
         truth on the reference's time axis, low-confidence runs, the reference-choice \
         spread (largest − smallest high confidence over every choice of first file; the medoid \
         against the best single file), and the alignment's error against the known warps \
         (`|τ(ψ̂(n)) − n|` in reference samples over every reference sample of every \
         demonstration but the reference: mean over seeds, the largest in brackets)",
    );
    let mut header = String::from(
        "| family | seeds | truth % | HC after fit % | LC runs after fit | spread pp (max) | \
         medoid − best pp | warp error: fit |",
    );
    let mut rule = String::from("|---|---|---|---|---|---|---|---|");
    for peer in &file.peer_warps {
        header.push_str(&format!(" warp error: {} ({}) |", peer.tool, peer.setting));
        rule.push_str("---|");
    }
    if file.peer_warps.is_empty() {
        s.push_str(".\n\n");
    } else {
        s.push_str(
            ", beside a peer's on the same demonstrations with the same weights \
             (`bench/peers/zoo_gdtw.py`; the fit's on the same seeds after \"fit\" where the \
             peer ran fewer).\n\n",
        );
    }
    s.push_str(&format!("{header}\n{rule}\n"));
    for f in &file.fit_rows {
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} ({}) | {} | {} |",
            f.family,
            f.seeds,
            num(f.truth_pct, 1),
            num(f.fit_high_pct, 1),
            num(f.fit_lc_runs, 1),
            f.spread_pp.map_or("—".into(), |v| num(v, 1)),
            f.spread_max_pp.map_or("—".into(), |v| num(v, 1)),
            f.medoid_vs_best_pp.map_or("—".into(), |v| num(v, 1)),
            match (f.warp_mean_samples, f.warp_max_samples) {
                (Some(m), Some(x)) => format!("{} ({})", num(m, 2), num(x, 1)),
                _ => "—".into(),
            },
        ));
        for peer in &file.peer_warps {
            s.push_str(&format!(" {} |", peer_cell(file, f, peer)));
        }
        s.push('\n');
    }
    let unmeasured: Vec<&str> = file
        .fit_rows
        .iter()
        .filter(|f| f.spread_pp.is_none() && f.family != SANDING)
        .map(|f| f.family.as_str())
        .collect();
    if !unmeasured.is_empty() {
        s.push_str(&format!(
            "\nReference-choice spread not measured for {} (every run of it was made with \
             `--no-spread`; `scripts/zoo_heldout.sh` measures it with each family's rounds).\n",
            unmeasured.join(", ")
        ));
    }
    s
}

/// Mean of the means and largest of the maxima of `(mean, max)` pairs; `None` for none.
fn mean_max(v: &[(f64, f64)]) -> Option<(f64, f64)> {
    (!v.is_empty()).then(|| {
        (
            v.iter().map(|p| p.0).sum::<f64>() / v.len() as f64,
            v.iter().map(|p| p.1).fold(0.0, f64::max),
        )
    })
}

/// The fit table's cell of `peer` for the family of `row`: its error over the seeds it ran,
/// and the fit's on the same seeds when those are fewer than the row's.
fn peer_cell(file: &ZooFile, row: &FitRow, peer: &PeerWarps) -> String {
    let tasks: Vec<&PeerTask> = peer
        .tasks
        .iter()
        .filter(|t| t.family == row.family)
        .collect();
    let Some((mean, max)) = mean_max(
        &tasks
            .iter()
            .map(|t| (t.mean_samples, t.max_samples))
            .collect::<Vec<_>>(),
    ) else {
        return "—".into();
    };
    let cell = format!("{} ({})", num(mean, 2), num(max, 1));
    if tasks.len() >= row.seeds {
        return cell;
    }
    let fit: Vec<(f64, f64)> = file
        .report
        .fits
        .iter()
        .filter(|f| f.family == row.family && tasks.iter().any(|t| t.seed == f.seed))
        .filter_map(|f| f.warp_error.as_ref())
        .map(|w| (w.mean_samples, w.max_samples))
        .collect();
    let seeds = tasks
        .iter()
        .map(|t| t.seed.to_string())
        .collect::<Vec<_>>()
        .join(",");
    match mean_max(&fit) {
        Some((fm, fx)) => format!(
            "{cell} on seeds {seeds}; fit {} ({})",
            num(fm, 2),
            num(fx, 1)
        ),
        None => format!("{cell} on seeds {seeds}"),
    }
}

/// Replaces the section of docs/zoo.md between `<!-- zoo:<set> -->` and
/// `<!-- /zoo:<set> -->` with `tables`; copies the held-out figure to docs/figures/zoo.png.
fn write_docs(root: &Path, file: &ZooFile, tables: &str, out: &Path) -> anyhow::Result<()> {
    let doc = root.join("docs/zoo.md");
    let text =
        std::fs::read_to_string(&doc).with_context(|| format!("reading {}", doc.display()))?;
    let (open, close) = (
        format!("<!-- zoo:{} -->", file.seed_set),
        format!("<!-- /zoo:{} -->", file.seed_set),
    );
    let (Some(a), Some(b)) = (text.find(&open), text.find(&close)) else {
        bail!(
            "{} has no section {open} … {close} for seed set {}: add the markers where the tables go",
            doc.display(),
            file.seed_set
        );
    };
    let new = format!("{}{open}\n{tables}{}", &text[..a], &text[b..]);
    std::fs::write(&doc, new).with_context(|| format!("writing {}", doc.display()))?;
    println!("updated {} ({open})", doc.display());
    if file.seed_set == "held-out" {
        let png = root.join("docs/figures/zoo.png");
        std::fs::copy(out.join("zoo.png"), &png)
            .with_context(|| format!("writing {}", png.display()))?;
        println!("wrote {}", png.display());
    }
    Ok(())
}

/// Image size (pixels; SVG user units).
const SIZE_PX: (u32, u32) = (1760, 620);

/// Draws the figure (module docs) as SVG and PNG.
fn draw(file: &ZooFile, svg: &Path, png: &Path) -> anyhow::Result<()> {
    tandem_plot::register_font()?;
    let mut svg_text = String::new();
    {
        let root = SVGBackend::with_string(&mut svg_text, SIZE_PX).into_drawing_area();
        draw_on(&root, file)?;
        root.present()
            .map_err(|e| anyhow!("finishing the zoo's SVG: {e}"))?;
    }
    {
        let root = BitMapBackend::new(png, SIZE_PX).into_drawing_area();
        draw_on(&root, file)?;
        root.present()
            .map_err(|e| anyhow!("writing {}: {e}", png.display()))?;
    }
    std::fs::write(svg, svg_text).with_context(|| format!("writing {}", svg.display()))?;
    Ok(())
}

fn draw_on<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    file: &ZooFile,
) -> anyhow::Result<()> {
    let err = |what: &'static str| {
        move |e: DrawingAreaErrorKind<DB::ErrorType>| {
            anyhow!("drawing the zoo's figure ({what}): {e}")
        }
    };
    root.fill(&WHITE).map_err(err("background"))?;
    let families = &file.report.families;
    let nf = families.len().max(1) as f64;
    // Two panels of equal width: at 45 % the right one's family names ran into each other.
    let (left, right) = root.split_horizontally(SIZE_PX.0 / 2);
    let rows = &file.family_rows;
    let x_of = |family: &str| families.iter().position(|f| f == family).unwrap_or(0) as f64;
    let robots: Vec<usize> = file.report.params.robots.clone();
    let offset = |k: usize| (k as f64 + 1.0) / (robots.len() as f64 + 1.0) - 0.5;
    let label = |v: &f64| {
        let i = v.round();
        if (v - i).abs() < 1e-9 && i >= 0.0 && (i as usize) < families.len() {
            families[i as usize].replace('_', " ")
        } else {
            String::new()
        }
    };

    // Left: final T_total over its bound.
    let top = rows
        .iter()
        .map(|r| r.t_total_s / r.bound_s)
        .filter(|v| v.is_finite())
        .fold(1.2, f64::max);
    let y_max = crate::fig5::nice_ceiling(top * 1.05);
    let mut chart = ChartBuilder::on(&left)
        .margin(20)
        .caption("final T_total / margin-free bound", (FONT_FAMILY, 22))
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(-0.5..nf - 0.5, 0.9..y_max)
        .map_err(err("left axes"))?;
    chart
        .configure_mesh()
        .x_labels(families.len())
        .x_label_formatter(&label)
        .x_label_style((FONT_FAMILY, 13))
        .y_label_formatter(&|v| format!("{v:.2}"))
        .y_desc("T_total / bound (mean over seeds)")
        .label_style((FONT_FAMILY, 16))
        .axis_desc_style((FONT_FAMILY, 18))
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.12))
        .draw()
        .map_err(err("left mesh"))?;
    for (target, dash) in [(1.0, false), (1.05, true), (1.10, true)] {
        let line = vec![(-0.5, target), (nf - 0.5, target)];
        if dash {
            chart
                .draw_series(DashedLineSeries::new(
                    line,
                    6,
                    6,
                    GROUND_TRUTH.stroke_width(1),
                ))
                .map_err(err("targets"))?;
        } else {
            chart
                .draw_series(LineSeries::new(line, GROUND_TRUTH.stroke_width(2)))
                .map_err(err("bound"))?;
        }
    }
    for (k, &n) in robots.iter().enumerate() {
        let colour = ROBOT_LC_N[k % ROBOT_LC_N.len()];
        for (cell, filled) in [(Cell::Rounds, true), (Cell::Continuous, false)] {
            let points: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.robots == n && r.cell == cell)
                .map(|r| (x_of(&r.family) + offset(k), r.t_total_s / r.bound_s))
                .filter(|p| p.1.is_finite())
                .collect();
            if points.is_empty() {
                continue;
            }
            let style = if filled {
                colour.filled()
            } else {
                colour.stroke_width(2)
            };
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 6, style)))
                .map_err(err("ratios"))?
                .label(format!("N = {n}, {}", cell_name(cell)))
                .legend(move |(x, y)| Circle::new((x + 10, y), 6, style));
        }
    }
    draw_legend!(
        chart,
        SeriesLabelPosition::UpperRight,
        14,
        err("left legend")
    )?;

    // Right: high confidence after learning (N = the first robot count, rounds) and after the
    // fit, against the truth.
    let mut chart = ChartBuilder::on(&right)
        .margin(20)
        .caption("high confidence against the truth", (FONT_FAMILY, 22))
        .x_label_area_size(50)
        .y_label_area_size(60)
        .build_cartesian_2d(-0.5..nf - 0.5, 0.0..110.0)
        .map_err(err("right axes"))?;
    chart
        .configure_mesh()
        .x_labels(families.len())
        .x_label_formatter(&label)
        .x_label_style((FONT_FAMILY, 12))
        .y_label_formatter(&|v| {
            if *v <= 100.0 {
                format!("{v:.0}")
            } else {
                String::new()
            }
        })
        .y_desc("reference samples (%)")
        .label_style((FONT_FAMILY, 16))
        .axis_desc_style((FONT_FAMILY, 18))
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.12))
        .draw()
        .map_err(err("right mesh"))?;
    let truth: Vec<(f64, f64)> = file
        .fit_rows
        .iter()
        .map(|f| (x_of(&f.family), f.truth_pct))
        .collect();
    chart
        .draw_series(truth.iter().map(|&(x, y)| {
            PathElement::new(
                vec![(x - 0.4, y), (x + 0.4, y)],
                GROUND_TRUTH.stroke_width(3),
            )
        }))
        .map_err(err("truth"))?
        .label("truth (never needs the operator)")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], GROUND_TRUTH.stroke_width(3)));
    chart
        .draw_series(file.fit_rows.iter().map(|f| {
            Circle::new(
                (x_of(&f.family) - 0.15, f.fit_high_pct),
                6,
                HIGH_CONFIDENCE.stroke_width(2),
            )
        }))
        .map_err(err("fit"))?
        .label("after the fit")
        .legend(|(x, y)| Circle::new((x + 10, y), 6, HIGH_CONFIDENCE.stroke_width(2)));
    if let Some(&n) = robots.first() {
        chart
            .draw_series(
                rows.iter()
                    .filter(|r| r.robots == n && r.cell == Cell::Rounds)
                    .map(|r| {
                        Circle::new(
                            (x_of(&r.family) + 0.15, r.high_pct),
                            6,
                            HIGH_CONFIDENCE.filled(),
                        )
                    }),
            )
            .map_err(err("learnt"))?
            .label(format!(
                "after {} rounds (N = {n})",
                file.report.params.rounds
            ))
            .legend(|(x, y)| Circle::new((x + 10, y), 6, HIGH_CONFIDENCE.filled()));
    }
    draw_legend!(
        chart,
        SeriesLabelPosition::UpperRight,
        14,
        err("right legend")
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seed_sets_by_name_and_by_list() {
        let (s, set) = seeds("select").unwrap();
        assert_eq!((s, set.as_str()), ((0..8).collect(), "select"));
        let (s, set) = seeds("held-out").unwrap();
        assert_eq!((s.len(), set.as_str()), (8, "held-out"));
        let (s, set) = seeds("1000, 1003").unwrap();
        assert_eq!((s, set.as_str()), (vec![1000, 1003], "held-out"));
        assert_eq!(seeds("3,1001").unwrap().1, "custom");
        let e = seeds("1,x").unwrap_err().to_string();
        assert!(e.contains("--seeds 1,x") && e.contains("held-out"), "{e}");
    }

    #[test]
    fn peer_files_of_one_setting_make_one_column() {
        let task = |family: &str, seed, mean_samples| PeerTask {
            family: family.into(),
            seed,
            pairs: 2,
            mean_samples,
            max_samples: 2.0 * mean_samples,
            wall_s: 1.0,
        };
        let file = |setting: &str, tasks| PeerWarps {
            tool: "gdtw 1.2.1".into(),
            setting: setting.into(),
            tasks,
        };
        let mut peers = Vec::new();
        add_peer(
            &mut peers,
            file("default", vec![task("painting", 1000, 1.0)]),
        );
        add_peer(
            &mut peers,
            file(
                "default",
                vec![task("deburring", 1000, 3.0), task("painting", 1000, 4.0)],
            ),
        );
        add_peer(&mut peers, file("best", vec![task("painting", 1000, 5.0)]));
        assert_eq!(peers.len(), 2);
        let means: Vec<(&str, f64)> = peers[0]
            .tasks
            .iter()
            .map(|t| (t.family.as_str(), t.mean_samples))
            .collect();
        assert_eq!(means, [("deburring", 3.0), ("painting", 4.0)]);
        assert_eq!(mean_max(&[(1.0, 3.0), (2.0, 5.0)]), Some((1.5, 5.0)));
        assert_eq!(mean_max(&[]), None);
    }

    #[test]
    fn numbers_print_a_dash_when_not_finite() {
        assert_eq!(num(1.234, 1), "1.2");
        assert_eq!(num(f64::NAN, 2), "—");
    }
}
