//! The tick thread's links to the DDS thread that cost the tick (almost) nothing: the commands
//! of every tick through a single-producer single-consumer ring of fixed-size records
//! ([`CommandRing`]), the state topics' [`Snapshot`] only when the DDS thread asks for it
//! ([`StateSlot`]), and the robots' progress as counters ([`Heard`]) instead of queued messages.
//!
//! Safe code only: every shared word is an atomic. The tick thread never waits on any of them
//! (a full ring drops the record and counts it; a slot the reader holds is written at the next
//! tick). Issue 43: "the tick's own cost with the node's queues attached against without"
//! (docs/decisions.md, "The node's tick: a command ring, a snapshot when asked, golden bytes and
//! the pose (issue 43)").

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use tandem_realtime::{MAX_ROBOTS, PerRobot, RobotFlags};

use crate::core::{Command, Snapshot};

/// Words of one command record for `n` robots: the tick, the flags, the tick's start (ns after
/// the ring's creation), then each robot's reference time and speed scale (`f64` bits).
const fn record_words(n: usize) -> usize {
    3 + 2 * n
}

/// A bounded single-producer single-consumer ring of [`Command`]s: the tick thread pushes one
/// per tick ([`CommandRing::push`], wait-free, no allocation), the DDS thread drains them
/// ([`CommandRing::pop`]). The producer publishes a record by a release store of its count
/// after writing its words; the consumer frees a slot by a release store of its own count
/// after reading them, so neither ever reads a half-written record. Each record carries the
/// instant its tick started, so the DDS thread stamps a command with its tick's time, not with
/// the time it got round to publishing it.
#[derive(Debug)]
pub struct CommandRing {
    n: usize,
    /// The instant the records' times count from.
    base: Instant,
    capacity: u64,
    words: Box<[AtomicU64]>,
    /// Records pushed so far (written by the producer only).
    head: AtomicU64,
    /// Records popped so far (written by the consumer only).
    tail: AtomicU64,
    /// Records the producer dropped because the ring was full.
    dropped: AtomicU64,
}

impl CommandRing {
    /// A ring of `capacity` (≥ 1) records of `n` (1…[`MAX_ROBOTS`]) robots.
    #[must_use]
    pub fn new(n: usize, capacity: usize) -> CommandRing {
        let n = n.clamp(1, MAX_ROBOTS);
        let capacity = capacity.max(1);
        CommandRing {
            n,
            base: Instant::now(),
            capacity: capacity as u64,
            words: (0..capacity * record_words(n))
                .map(|_| AtomicU64::new(0))
                .collect(),
            head: AtomicU64::new(0),
            tail: AtomicU64::new(0),
            dropped: AtomicU64::new(0),
        }
    }

    fn record(&self, count: u64) -> &[AtomicU64] {
        let w = record_words(self.n);
        let at = (count % self.capacity) as usize * w;
        &self.words[at..at + w]
    }

    /// Pushes `cmd` of the tick that started at `at` (the producer, one thread); `false` (and
    /// counted) when the ring is full.
    pub fn push(&self, cmd: &Command, at: Instant) -> bool {
        let h = self.head.load(Ordering::Relaxed);
        if h - self.tail.load(Ordering::Acquire) >= self.capacity {
            self.dropped.fetch_add(1, Ordering::Relaxed);
            return false;
        }
        let r = self.record(h);
        r[0].store(cmd.tick, Ordering::Relaxed);
        r[1].store(cmd.flags_word(), Ordering::Relaxed);
        // Nanoseconds fit a u64 for 584 years.
        let since = at.saturating_duration_since(self.base).as_nanos() as u64;
        r[2].store(since, Ordering::Relaxed);
        for k in 0..self.n.min(cmd.ref_time.len()) {
            r[3 + 2 * k].store(cmd.ref_time[k].to_bits(), Ordering::Relaxed);
            r[4 + 2 * k].store(cmd.speed[k].to_bits(), Ordering::Relaxed);
        }
        self.head.store(h + 1, Ordering::Release);
        true
    }

    /// Pops the oldest command and the instant its tick started (the consumer, one thread), or
    /// `None` when the ring is empty.
    pub fn pop(&self) -> Option<(Command, Instant)> {
        let t = self.tail.load(Ordering::Relaxed);
        if t == self.head.load(Ordering::Acquire) {
            return None;
        }
        let r = self.record(t);
        let mut ref_time = PerRobot::<f64>::new(self.n);
        let mut speed = PerRobot::<f64>::new(self.n);
        for k in 0..self.n {
            ref_time.as_mut_slice()[k] = f64::from_bits(r[3 + 2 * k].load(Ordering::Relaxed));
            speed.as_mut_slice()[k] = f64::from_bits(r[4 + 2 * k].load(Ordering::Relaxed));
        }
        let at = self.base + Duration::from_nanos(r[2].load(Ordering::Relaxed));
        let cmd = Command::from_words(
            r[0].load(Ordering::Relaxed),
            r[1].load(Ordering::Relaxed),
            ref_time,
            speed,
        );
        self.tail.store(t + 1, Ordering::Release);
        Some((cmd, at))
    }

    /// Records dropped because the ring was full (the DDS thread behind by `capacity` ticks).
    #[must_use]
    pub fn dropped(&self) -> u64 {
        self.dropped.load(Ordering::Relaxed)
    }
}

/// The state topics' [`Snapshot`], written by the tick thread only when the DDS thread has asked
/// ([`StateSlot::ask`], at the state topics' rate) or the cell's fault or round state changed.
/// The tick thread's write is a `try_lock` (never waits: a slot the reader holds is written at a
/// later tick), the reader's lock is held for one copy.
#[derive(Debug, Default)]
pub struct StateSlot {
    want: AtomicBool,
    slot: Mutex<Option<Snapshot>>,
}

impl StateSlot {
    /// An empty slot that wants the first snapshot.
    #[must_use]
    pub fn new() -> StateSlot {
        StateSlot {
            want: AtomicBool::new(true),
            slot: Mutex::new(None),
        }
    }

    /// Whether the reader waits for a snapshot (one relaxed load: the tick thread's per-tick
    /// cost when it does not).
    #[must_use]
    pub fn wanted(&self) -> bool {
        self.want.load(Ordering::Relaxed)
    }

    /// The reader asks for the next snapshot.
    pub fn ask(&self) {
        self.want.store(true, Ordering::Relaxed);
    }

    /// The writer (the tick thread) puts `snap` in unless the reader holds the slot right now;
    /// `true` when written (the request is then answered).
    pub fn put(&self, snap: Snapshot) -> bool {
        match self.slot.try_lock() {
            Ok(mut g) => {
                *g = Some(snap);
                self.want.store(false, Ordering::Relaxed);
                true
            }
            Err(_) => false,
        }
    }

    /// The reader takes the snapshot written since its last take, if any.
    pub fn take(&self) -> Option<Snapshot> {
        match self.slot.lock() {
            Ok(mut g) => g.take(),
            Err(poisoned) => poisoned.into_inner().take(),
        }
    }
}

/// Per robot, the number of progress messages the DDS thread has heard: the tick thread
/// compares each with the count it last saw ([`Heard::changed`]) instead of draining one
/// queued message per report (a robot's liveness needs only that it reported).
#[derive(Debug)]
pub struct Heard {
    counts: [AtomicU64; MAX_ROBOTS],
}

impl Default for Heard {
    fn default() -> Self {
        Heard {
            counts: std::array::from_fn(|_| AtomicU64::new(0)),
        }
    }
}

impl Heard {
    /// The DDS thread heard robot `robot` (0-based; others ignored).
    pub fn hear(&self, robot: usize) {
        if let Some(c) = self.counts.get(robot) {
            c.fetch_add(1, Ordering::Relaxed);
        }
    }

    /// The robots (of the first `n`) heard since `seen` (updated): a flag each.
    pub fn changed(&self, n: usize, seen: &mut [u64; MAX_ROBOTS]) -> RobotFlags {
        let mut out = RobotFlags::new(n);
        for (k, (c, s)) in self.counts.iter().zip(seen.iter_mut()).take(n).enumerate() {
            let v = c.load(Ordering::Relaxed);
            if v != *s {
                *s = v;
                out.set(k, true);
            }
        }
        out
    }
}

/// A counter of messages the DDS thread queued for the tick thread, so the tick thread reads
/// its queue only when it moved (one relaxed load otherwise).
#[derive(Debug, Default)]
pub struct Pending {
    sent: AtomicU64,
}

impl Pending {
    /// The DDS thread queued one more message.
    pub fn sent(&self) {
        self.sent.fetch_add(1, Ordering::Release);
    }

    /// Whether messages were queued since `seen` (updated).
    pub fn moved(&self, seen: &mut u64) -> bool {
        let v = self.sent.load(Ordering::Acquire);
        if v == *seen {
            false
        } else {
            *seen = v;
            true
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cmd(tick: u64, n: usize) -> Command {
        let mut ref_time = PerRobot::<f64>::new(n);
        let mut speed = PerRobot::<f64>::new(n);
        let mut needs = RobotFlags::new(n);
        for k in 0..n {
            ref_time.as_mut_slice()[k] = tick as f64 + 0.25 * k as f64;
            speed.as_mut_slice()[k] = 0.5 * k as f64;
        }
        needs.set(n - 1, tick.is_multiple_of(2));
        Command {
            tick,
            active: true,
            finished: false,
            fault: tick.is_multiple_of(3),
            ref_time,
            speed,
            needs_operator: needs,
        }
    }

    #[test]
    fn the_ring_round_trips_in_order_and_drops_when_full() {
        let ring = CommandRing::new(3, 4);
        assert!(ring.pop().is_none());
        // Each tick 1.5 ms after the ring's creation times its number; nanoseconds exact.
        let at = |t: u64| ring.base + Duration::from_micros(1_500 * t);
        for t in 1..=4 {
            assert!(ring.push(&cmd(t, 3), at(t)));
        }
        assert!(!ring.push(&cmd(5, 3), at(5)), "a full ring refuses");
        assert_eq!(ring.dropped(), 1);
        for t in 1..=2 {
            assert_eq!(ring.pop(), Some((cmd(t, 3), at(t))));
        }
        // Wraps around.
        for t in 6..=7 {
            assert!(ring.push(&cmd(t, 3), at(t)));
        }
        let got: Vec<(u64, Instant)> = std::iter::from_fn(|| ring.pop())
            .map(|(c, i)| (c.tick, i))
            .collect();
        assert_eq!(got, [3, 4, 6, 7].map(|t| (t, at(t))));
        // An instant before the ring existed is its creation.
        assert!(ring.push(&cmd(8, 3), ring.base - Duration::from_millis(1)));
        assert_eq!(ring.pop().map(|(_, i)| i), Some(ring.base));
    }

    #[test]
    fn the_ring_between_two_threads_keeps_every_record_whole() {
        let ring = std::sync::Arc::new(CommandRing::new(8, 16));
        let r = ring.clone();
        let base = ring.base;
        let producer = std::thread::spawn(move || {
            let mut t = 1;
            while t <= 3_000 {
                if r.push(&cmd(t, 8), base + Duration::from_nanos(t)) {
                    t += 1;
                }
            }
        });
        let mut next = 1;
        while next <= 3_000 {
            if let Some(c) = ring.pop() {
                assert_eq!(
                    c,
                    (cmd(next, 8), base + Duration::from_nanos(next)),
                    "record {next} torn or out of order"
                );
                next += 1;
            }
        }
        producer.join().unwrap();
    }

    #[test]
    fn progress_counters_report_each_robot_once() {
        let heard = Heard::default();
        let mut seen = [0; MAX_ROBOTS];
        assert_eq!(heard.changed(3, &mut seen).count(), 0);
        heard.hear(1);
        heard.hear(1);
        heard.hear(9);
        let c = heard.changed(3, &mut seen);
        assert_eq!(c, [false, true, false]);
        assert_eq!(heard.changed(3, &mut seen).count(), 0);
    }

    #[test]
    fn the_pending_counter_moves_once_per_batch() {
        let pending = Pending::default();
        let mut seen = 0;
        assert!(!pending.moved(&mut seen));
        pending.sent();
        assert!(pending.moved(&mut seen));
        assert!(!pending.moved(&mut seen));
    }
}
