//! The control loop's tick cost with a console attached against without, in the same run
//! (issue 42: at most 1.1×): `bare` ticks a three-robot rounds coordinator; `with_console`
//! ticks the same one, applies the (empty) control queue at the tick boundary and publishes
//! the snapshot to a running console server. Run with
//! `cargo bench -p tandem-console --bench handle`.
#![expect(
    missing_docs,
    reason = "criterion_group! generates an undocumented pub fn"
)]

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use tandem_console::{Console, ConsoleConfig, Driver, Geometry};
use tandem_realtime::{Controller, Operator};

#[path = "../tests/support/mod.rs"]
mod support;

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("tick");
    let mut bare = support::rounds(3);
    group.bench_function("bare", |b| {
        b.iter(|| {
            if bare.is_finished() {
                bare.reset();
            }
            black_box(bare.tick(Operator::Scheduled).expect("a valid operator"))
        });
    });
    let mut ctl = support::rounds(3);
    let (console, mut handle) =
        Console::start(&ConsoleConfig::default(), Geometry::new(&ctl)).expect("a free port");
    group.bench_function("with_console", |b| {
        b.iter(|| {
            if ctl.is_finished() {
                ctl.reset();
            }
            if Driver::apply(&mut handle, &mut ctl) {
                let t = ctl.tick(Operator::Scheduled).expect("a valid operator");
                handle.publish(&t, &ctl);
                black_box(t);
            }
        });
    });
    group.finish();
    console.stop();
}

criterion_group!(benches, bench);
criterion_main!(benches);
