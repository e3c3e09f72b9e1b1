//! The tick thread's links to the DDS thread that cost the tick (almost) nothing: the commands
//! of every tick through a single-producer single-consumer ring of fixed-size records
//! ([`CommandRing`]), the state topics' [`Snapshot`] only when the DDS thread asks for it
//! ([`StateSlot`]), and the robots' progress as counters ([`Heard`]) instead of queued messages.
//!
//! Safe code only: every shared word is an atomic. The tick thread never waits on any of them
//! (a full ring drops the record and counts it; a slot the reader holds is written at the next
//! tick), and it does not wake the DDS thread each tick: each record announces the next tick's
//! deadline, by which the DDS thread sleeps ([`WriterSchedule`]); the tick thread wakes it only
//! when the ring is half full or a reply waits (docs/decisions.md, "The node's DDS thread sleeps
//! by the tick's announced deadline, no wake per tick (issue 43)"). Issue 43: "the tick's own cost with the node's queues attached against without"
//! (docs/decisions.md, "The node's tick: a command ring, a snapshot when asked, golden bytes and
//! the pose (issue 43)").

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use tandem_realtime::{MAX_ROBOTS, RobotFlags};

use crate::core::{CellLoop, Command, Snapshot};
use crate::error::Result;

/// Words of one command record for `n` robots: the tick, the flags, the tick's start and the
/// next tick's deadline (ns after the ring's creation; [`NO_DEADLINE`]: none announced), then
/// each robot's reference time and speed scale (`f64` bits).
const fn record_words(n: usize) -> usize {
    HEAD_WORDS + 2 * n
}

/// The leading words of a record: tick, flags, start, next deadline.
const HEAD_WORDS: usize = 4;

/// A record's next-deadline word when its tick announced none ([`CommandRing::push`], the
/// tick thread's last command).
const NO_DEADLINE: u64 = u64::MAX;

/// What a push did, for the tick thread's decision to wake the DDS thread.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Push {
    /// Stored; the ring held fewer than half its capacity.
    Stored,
    /// Stored into a ring at least half full: the DDS thread is behind, wake it.
    Wake,
    /// The ring was full: dropped and counted (wake the DDS thread too).
    Dropped,
}

/// A value alone on its cache lines: 128 bytes, two 64-byte lines, as x86's adjacent-line
/// prefetcher pairs them. The words one thread writes share no line with words the other thread
/// writes, so a store of one thread does not take a line the other is about to read.
#[derive(Debug, Default)]
#[repr(align(128))]
struct OwnLine<T>(T);

/// The ring's words the producer (the tick thread) writes.
#[derive(Debug, Default)]
struct ProducerEnd {
    /// Records pushed so far.
    head: AtomicU64,
    /// The consumer's count as the producer last read it: a lower bound of it, so every slot
    /// below it is free without reading the consumer's line again.
    tail_seen: AtomicU64,
    /// Records dropped because the ring was full.
    dropped: AtomicU64,
}

/// The ring's words the consumer (the DDS thread) writes.
#[derive(Debug, Default)]
struct ConsumerEnd {
    /// Records popped so far.
    tail: AtomicU64,
    /// The producer's count as the consumer last read it: every record below it is written.
    head_seen: AtomicU64,
    /// The next tick's deadline the last popped record announced (ns in the ring's time,
    /// [`NO_DEADLINE`] before the first pop).
    next_ns: AtomicU64,
}

/// A bounded single-producer single-consumer ring of [`Command`]s: the tick thread pushes one
/// per tick ([`CommandRing::push`], wait-free, no allocation), the DDS thread drains them
/// ([`CommandRing::pop`]). The producer publishes a record by a release store of its count
/// after writing its words; the consumer frees a slot by a release store of its own count
/// after reading them, so neither ever reads a half-written record. Each end keeps the other's
/// count as it last read it (an acquire load) and reads it again only when that says full
/// (producer) or empty (consumer), and each end's words are on cache lines of their own: a push
/// into a ring with room reads no line the consumer writes. Each record carries the instant its
/// tick started, so the DDS thread stamps a command with its tick's time, not with the time it
/// got round to publishing it, and the deadline of the tick after it
/// ([`CommandRing::next_deadline`]), by which the DDS thread sleeps: the tick thread does not
/// wake it per record, only when a push finds the ring half full (the DDS thread behind).
#[derive(Debug)]
pub struct CommandRing {
    n: usize,
    /// The instant the records' times count from.
    base: Instant,
    capacity: u64,
    /// Unread records at which a push asks for the DDS thread's wake: half the capacity (≥ 1).
    wake_fill: u64,
    words: Box<[AtomicU64]>,
    /// Written by the producer only.
    producer: OwnLine<ProducerEnd>,
    /// Written by the consumer only.
    consumer: OwnLine<ConsumerEnd>,
}

impl CommandRing {
    /// A ring of at least `capacity` records of `n` (1…[`MAX_ROBOTS`]) robots: `capacity`
    /// rounded up to a power of two (≥ 1), so that a record's slot is its count masked, not a
    /// division.
    #[must_use]
    pub fn new(n: usize, capacity: usize) -> CommandRing {
        let n = n.clamp(1, MAX_ROBOTS);
        let capacity = capacity.max(1).next_power_of_two();
        CommandRing {
            n,
            base: Instant::now(),
            capacity: capacity as u64,
            wake_fill: (capacity as u64 / 2).max(1),
            words: (0..capacity * record_words(n))
                .map(|_| AtomicU64::new(0))
                .collect(),
            producer: OwnLine::default(),
            consumer: OwnLine(ConsumerEnd {
                next_ns: AtomicU64::new(NO_DEADLINE),
                ..ConsumerEnd::default()
            }),
        }
    }

    /// The record of the `count`-th push: its tick, flags, start and next deadline, then each
    /// robot's reference time and speed scale as a pair.
    #[inline]
    fn record(&self, count: u64) -> (&[AtomicU64; HEAD_WORDS], &[[AtomicU64; 2]]) {
        let w = record_words(self.n);
        let at = (count & (self.capacity - 1)) as usize * w;
        let r = &self.words[at..at + w];
        let (head, robots) = r.split_at(HEAD_WORDS);
        (
            head.try_into().expect("a record has four leading words"),
            robots.as_chunks::<2>().0,
        )
    }

    /// Pushes `cmd` of the tick that started at `at` (the producer, one thread), announcing no
    /// next deadline (the tick thread's last command); `false` (and counted) when the ring is
    /// full.
    pub fn push(&self, cmd: &Command, at: Instant) -> bool {
        let at_ns = self.since(at);
        let words = (cmd.tick, cmd.flags_word(), at_ns, NO_DEADLINE);
        self.push_words(words, &cmd.ref_time, &cmd.speed) != Push::Dropped
    }

    /// [`push`](Self::push) announcing `next`, the deadline of the tick after this one: the
    /// DDS thread sleeps until just past it ([`WriterSchedule`]) instead of being woken.
    pub fn push_until(&self, cmd: &Command, at: Instant, next: Instant) -> bool {
        let words = (cmd.tick, cmd.flags_word(), self.since(at), self.since(next));
        self.push_words(words, &cmd.ref_time, &cmd.speed) != Push::Dropped
    }

    /// `at` in the records' time: ns after the ring's creation (0 before it).
    #[inline]
    fn since(&self, at: Instant) -> u64 {
        // Nanoseconds fit a u64 for 584 years.
        at.saturating_duration_since(self.base).as_nanos() as u64
    }

    /// [`push`](Self::push) of a command given as its head words (its tick count, its
    /// [`Command::flags_word`], its tick's start and the next tick's deadline, both as
    /// [`since`](Self::since) gives them) and its robots' reference times and speed scales (the
    /// node's tick thread takes them from the loop, [`TickEnd::tick`]: no [`Command`] is
    /// built). [`Push::Wake`] when the ring held half its capacity or more: the consumer's
    /// count is read only when the count last seen says so, so a ring the DDS thread keeps
    /// drained costs one read of its line per half ring of pushes.
    #[inline]
    pub(crate) fn push_words(
        &self,
        (tick, flags, at_ns, next_ns): (u64, u64, u64, u64),
        ref_time: &[f64],
        speed: &[f64],
    ) -> Push {
        let p = &self.producer.0;
        let h = p.head.load(Ordering::Relaxed);
        let mut pushed = Push::Stored;
        if h - p.tail_seen.load(Ordering::Relaxed) >= self.wake_fill {
            // Half full as last seen: read the consumer's count (every slot below it was read
            // before its release store, which this acquire load orders before our writes).
            let t = self.consumer.0.tail.load(Ordering::Acquire);
            p.tail_seen.store(t, Ordering::Relaxed);
            if h - t >= self.capacity {
                p.dropped
                    .store(p.dropped.load(Ordering::Relaxed) + 1, Ordering::Relaxed);
                return Push::Dropped;
            }
            if h - t >= self.wake_fill {
                pushed = Push::Wake;
            }
        }
        let (head, robots) = self.record(h);
        head[0].store(tick, Ordering::Relaxed);
        head[1].store(flags, Ordering::Relaxed);
        head[2].store(at_ns, Ordering::Relaxed);
        head[3].store(next_ns, Ordering::Relaxed);
        for ((pair, r), s) in robots.iter().zip(ref_time).zip(speed) {
            pair[0].store(r.to_bits(), Ordering::Relaxed);
            pair[1].store(s.to_bits(), Ordering::Relaxed);
        }
        p.head.store(h + 1, Ordering::Release);
        pushed
    }

    /// Pops the oldest command and the instant its tick started (the consumer, one thread), or
    /// `None` when the ring is empty. Builds a fresh [`Command`]; the node's DDS thread reuses
    /// one ([`pop_into`](Self::pop_into)).
    pub fn pop(&self) -> Option<(Command, Instant)> {
        let mut cmd = Command::idle(self.n);
        self.pop_into(&mut cmd).map(|at| (cmd, at))
    }

    /// [`pop`](Self::pop) into `cmd`, which the consumer keeps from one pop to the next:
    /// every field of `cmd` is overwritten with the oldest record (its robots' count becomes
    /// the ring's), nothing is zeroed first; returns the instant its tick started, or `None`
    /// (and `cmd` untouched) when the ring is empty.
    pub fn pop_into(&self, cmd: &mut Command) -> Option<Instant> {
        let c = &self.consumer.0;
        let t = c.tail.load(Ordering::Relaxed);
        if t == c.head_seen.load(Ordering::Relaxed) {
            // Empty as last seen: read the producer's count (every record below it was written
            // before its release store, which this acquire load orders before our reads).
            let h = self.producer.0.head.load(Ordering::Acquire);
            c.head_seen.store(h, Ordering::Relaxed);
            if t == h {
                return None;
            }
        }
        let (head, robots) = self.record(t);
        if cmd.ref_time.len() != self.n
            || cmd.speed.len() != self.n
            || cmd.needs_operator.len() != self.n
        {
            // A command of another robot count: once, on the first pop into it.
            *cmd = Command::idle(self.n);
        }
        for ((pair, r), s) in robots
            .iter()
            .zip(cmd.ref_time.as_mut_slice())
            .zip(cmd.speed.as_mut_slice())
        {
            *r = f64::from_bits(pair[0].load(Ordering::Relaxed));
            *s = f64::from_bits(pair[1].load(Ordering::Relaxed));
        }
        let at = self.base + Duration::from_nanos(head[2].load(Ordering::Relaxed));
        cmd.tick = head[0].load(Ordering::Relaxed);
        cmd.set_flags_word(head[1].load(Ordering::Relaxed));
        c.next_ns
            .store(head[3].load(Ordering::Relaxed), Ordering::Relaxed);
        c.tail.store(t + 1, Ordering::Release);
        Some(at)
    }

    /// The deadline of the tick after the last popped one, as that tick announced it (the
    /// consumer's; `None` before the first pop and after a record that announced none): the
    /// next record is due when that tick has run, so the DDS thread sleeps until just past it.
    #[must_use]
    pub fn next_deadline(&self) -> Option<Instant> {
        match self.consumer.0.next_ns.load(Ordering::Relaxed) {
            NO_DEADLINE => None,
            ns => Some(self.base + Duration::from_nanos(ns)),
        }
    }

    /// Records dropped because the ring was full (the DDS thread behind by `capacity` ticks).
    #[must_use]
    pub fn dropped(&self) -> u64 {
        self.producer.0.dropped.load(Ordering::Relaxed)
    }

    /// Records the ring holds at most ([`CommandRing::new`]'s `capacity` rounded up to a power
    /// of two).
    #[must_use]
    pub fn capacity(&self) -> usize {
        self.capacity as usize
    }
}

/// When the node's DDS thread wakes, from the deadline the tick thread announced with its last
/// command ([`CommandRing::next_deadline`], `D`): `lead` before `D` to take the network's
/// messages in (progress, the operator, requests), so the tick at `D` reads them; `after` past
/// `D` to publish that tick's command; at least every `poll` (the network's messages, the
/// record thread's results, a tick thread that announced nothing). When it wakes past
/// `D + after` and the command is not in the ring yet (the tick thread late), it sleeps again
/// `retry`, doubled at each such wake in a row up to `poll`: never a spin.
///
/// The wait of a command in the ring (its push → the DDS thread's pop), both threads sleeping
/// with the kernel's timer slack `s` (50 µs for a thread that is not real-time): the tick
/// starts in `[D, D + s]` and pushes within its work; the DDS thread wakes in
/// `[D + after, D + after + s]`. Woken after the push, the command waited < `after + s`; woken
/// before it, the DDS thread sleeps `retry` and wakes < `retry + s` after the push when the
/// push came within `retry` of that wake: ≤ 70 µs either way with [`WriterSchedule::NODE`]. A
/// tick that starts `L` late (its thread not run) finds the retries doubled to < `2L + retry`
/// (at most `poll`), plus `s`. Add the scheduler's delay of a runnable thread, as for a woken
/// one (docs/decisions.md, "The node's DDS thread sleeps by the tick's announced deadline, no
/// wake per tick (issue 43)").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WriterSchedule {
    /// How long before a tick's deadline the DDS thread takes the network's messages in.
    pub lead: Duration,
    /// How long after a tick's deadline it wakes for that tick's command.
    pub after: Duration,
    /// Its first sleep when it woke for a command not pushed yet (doubled each time).
    pub retry: Duration,
    /// Its longest sleep.
    pub poll: Duration,
}

impl WriterSchedule {
    /// The node's: `lead` 200 µs (the polling period of the DDS thread before, so a message is
    /// read by the next tick when it arrives ≥ 200 µs before it, as then), `after` 20 µs,
    /// `retry` 20 µs, `poll` 1 ms.
    pub const NODE: WriterSchedule = WriterSchedule {
        lead: Duration::from_micros(200),
        after: Duration::from_micros(20),
        retry: Duration::from_micros(20),
        poll: Duration::from_millis(1),
    };

    /// The sleep from `now` after a pass that found nothing to do, when the tick announced
    /// `next` ([`CommandRing::next_deadline`]) and `late` passes in a row have found that
    /// tick's command missing past `next + after` ([`is_late`](Self::is_late)).
    #[must_use]
    pub fn sleep(&self, now: Instant, next: Option<Instant>, late: u32) -> Duration {
        let Some(next) = next else {
            return self.poll;
        };
        let until = |t: Instant| t.saturating_duration_since(now).min(self.poll);
        if let Some(before) = next.checked_sub(self.lead)
            && now < before
        {
            return until(before);
        }
        let publish = next + self.after;
        if now < publish {
            return until(publish);
        }
        self.retry.saturating_mul(1 << late.min(16)).min(self.poll)
    }

    /// Whether a pass at `now` that found no command came past `next + after`: the tick that
    /// announced `next` has not pushed its command yet.
    #[must_use]
    pub fn is_late(&self, now: Instant, next: Option<Instant>) -> bool {
        next.is_some_and(|d| now >= d + self.after)
    }
}

/// The state topics' [`Snapshot`], written by the tick thread only when the DDS thread has asked
/// ([`StateSlot::ask`], at the state topics' rate) or the cell's fault or round state changed.
/// The tick thread's write is a `try_lock` (never waits: a slot the reader holds is written at a
/// later tick), the reader's lock is held for one copy. The request flag, which the tick thread
/// reads every tick, is on cache lines of its own: the reader's lock and unlock of the slot on
/// each of its passes do not take the line the tick thread reads.
#[derive(Debug, Default)]
pub struct StateSlot {
    want: OwnLine<AtomicBool>,
    slot: Mutex<Option<Snapshot>>,
}

impl StateSlot {
    /// An empty slot that wants the first snapshot.
    #[must_use]
    pub fn new() -> StateSlot {
        StateSlot {
            want: OwnLine(AtomicBool::new(true)),
            slot: Mutex::new(None),
        }
    }

    /// Whether the reader waits for a snapshot (one relaxed load: the tick thread's per-tick
    /// cost when it does not).
    #[inline]
    #[must_use]
    pub fn wanted(&self) -> bool {
        self.want.0.load(Ordering::Relaxed)
    }

    /// The reader asks for the next snapshot.
    pub fn ask(&self) {
        self.want.0.store(true, Ordering::Relaxed);
    }

    /// The writer (the tick thread) puts `snap` in unless the reader holds the slot right now;
    /// `true` when written (the request is then answered).
    pub fn put(&self, snap: Snapshot) -> bool {
        match self.slot.try_lock() {
            Ok(mut g) => {
                *g = Some(snap);
                self.want.0.store(false, Ordering::Relaxed);
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
/// queued message per report (a robot's liveness needs only that it reported). Aligned to
/// 128 bytes: no word the tick thread writes shares its cache lines.
#[derive(Debug)]
#[repr(align(128))]
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
    ///
    /// One writer only (the node's DDS thread): the count moves by a relaxed load and a
    /// relaxed store, not a read-modify-write (on x86 a `lock xadd`, ≈ 20 cycles, against two
    /// plain moves). Two threads hearing the same robot at once could lose one count, never
    /// make one up; the tick thread only asks whether the count changed ([`Heard::each_heard`]),
    /// so a lost count of two concurrent reports still reads as heard.
    #[inline]
    pub fn hear(&self, robot: usize) {
        if let Some(c) = self.counts.get(robot) {
            c.store(c.load(Ordering::Relaxed).wrapping_add(1), Ordering::Relaxed);
        }
    }

    /// The robots (of the first `n`) heard since `seen` (updated): a flag each.
    pub fn changed(&self, n: usize, seen: &mut [u64; MAX_ROBOTS]) -> RobotFlags {
        let mut out = RobotFlags::new(n);
        self.each_heard(n, seen, |k| out.set(k, true));
        out
    }

    /// Calls `f(k)` for each robot `k` (of the first `n`) heard since `seen` (updated), robot 1
    /// first: one relaxed load and one comparison per robot.
    #[inline]
    pub fn each_heard(&self, n: usize, seen: &mut [u64; MAX_ROBOTS], mut f: impl FnMut(usize)) {
        let n = n.min(MAX_ROBOTS);
        for (k, (c, s)) in self.counts[..n].iter().zip(&mut seen[..n]).enumerate() {
            let v = c.load(Ordering::Relaxed);
            if v != *s {
                *s = v;
                f(k);
            }
        }
    }
}

/// A counter of messages the DDS thread queued for the tick thread, so the tick thread reads
/// its queue only when it moved (one relaxed load otherwise). Aligned to 128 bytes, as
/// [`Heard`].
#[derive(Debug, Default)]
#[repr(align(128))]
pub struct Pending {
    sent: AtomicU64,
}

impl Pending {
    /// The DDS thread queued one more message.
    pub fn sent(&self) {
        self.sent.fetch_add(1, Ordering::Release);
    }

    /// Whether messages were queued since `seen` (updated).
    #[inline]
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

/// What the tick thread and the DDS thread share besides the bounded queue of rare messages:
/// the links above and the tick thread's counters for [`crate::NodeStats`] (each written by
/// the tick thread only, by a plain store).
#[derive(Debug)]
pub struct Links {
    /// Every tick's command, to the DDS thread.
    pub commands: CommandRing,
    /// The state topics' snapshot, when the DDS thread asks.
    pub state: StateSlot,
    /// The robots' progress reports, counted.
    pub heard: Heard,
    /// Messages queued for the tick thread, counted.
    pub pending: Pending,
    /// Ticks run.
    pub ticks: AtomicU64,
    /// The longest time between two tick starts (ns).
    pub max_period_ns: AtomicU64,
    /// The longest time one tick's work took (ns).
    pub max_tick_ns: AtomicU64,
}

impl Links {
    /// The links of `n` robots with a command ring of at least `capacity` records.
    #[must_use]
    pub fn new(n: usize, capacity: usize) -> Links {
        Links {
            commands: CommandRing::new(n, capacity),
            state: StateSlot::new(),
            heard: Heard::default(),
            pending: Pending::default(),
            ticks: AtomicU64::new(0),
            max_period_ns: AtomicU64::new(0),
            max_tick_ns: AtomicU64::new(0),
        }
    }
}

/// The tick thread's end of the [`Links`]: what it last saw of each counter and the counters it
/// keeps, so that one tick ([`TickEnd::tick`]) is a few loads and stores around
/// [`CellLoop::advance`]. The node's tick thread runs exactly this (and the benchmark and the
/// instruction-count example run it too).
#[derive(Debug)]
pub struct TickEnd {
    n: usize,
    pending_seen: u64,
    heard_seen: [u64; MAX_ROBOTS],
    /// The last command's active, finished and fault flags (bits 0–2 of
    /// [`Command::flags_word`]).
    last_flags: u64,
    /// A snapshot is owed: the slot was held by the reader when one was due.
    owed: bool,
    ticks: u64,
    /// The last tick's start, and as ns in the ring's time ([`CommandRing::since`]); the one
    /// before it in the ring's time.
    start: Option<Instant>,
    start_ns: u64,
    last_start_ns: Option<u64>,
    max_period_ns: u64,
    max_tick: Duration,
}

impl TickEnd {
    /// The tick thread's end for `n` robots, nothing seen yet.
    #[must_use]
    pub fn new(n: usize) -> TickEnd {
        TickEnd {
            n: n.min(MAX_ROBOTS),
            pending_seen: 0,
            heard_seen: [0; MAX_ROBOTS],
            last_flags: 0,
            owed: false,
            ticks: 0,
            start: None,
            start_ns: 0,
            last_start_ns: None,
            max_period_ns: 0,
            max_tick: Duration::ZERO,
        }
    }

    /// One tick at `now` (the tick's start), the next to start at `next`: `drain` takes the
    /// queued rare messages in when the pending counter moved, each robot heard since the last
    /// tick is alive at `now`, the loop's tick ([`CellLoop::advance`] without building its
    /// [`Command`]), the command's words from the loop into the ring with `next` as the DDS
    /// thread's next deadline (a full ring drops it, counted), and the snapshot into
    /// the state slot when the DDS thread asked for it or the fault, the round's end or the
    /// running state changed (or one is owed). The ring's record is the command `advance`
    /// returns (`cargo test -p tandem-ros2 --test cell_loop the_tick_thread`); whether the
    /// round finished is [`CellLoop::is_finished`]. `true` when the DDS thread should be woken
    /// now: the ring was half full or full (it is behind its deadlines); otherwise it wakes by
    /// `next` ([`WriterSchedule`]).
    ///
    /// # Errors
    /// [`CellLoop::advance`]'s.
    pub fn tick(
        &mut self,
        l: &mut CellLoop,
        links: &Links,
        now: Instant,
        next: Instant,
        drain: impl FnOnce(&mut CellLoop),
    ) -> Result<bool> {
        if links.pending.moved(&mut self.pending_seen) {
            drain(l);
        }
        links
            .heard
            .each_heard(self.n, &mut self.heard_seen, |k| l.heard(k, now));
        l.tick_at(now)?;
        // The tick's start in the ring's time, for its record and the period's count.
        let start_ns = links.commands.since(now);
        self.last_start_ns = self.start.map(|_| self.start_ns);
        self.start = Some(now);
        self.start_ns = start_ns;
        let (tick, flags, ref_time, speed) = l.command_words();
        let next_ns = links.commands.since(next);
        let pushed = links
            .commands
            .push_words((tick, flags, start_ns, next_ns), ref_time, speed);
        // Active, finished, fault.
        let flags = flags & 0b111;
        if flags != self.last_flags || self.owed || links.state.wanted() {
            // A slot the DDS thread holds right now is written at the next tick.
            self.owed = !links.state.put(l.snapshot());
        }
        self.last_flags = flags;
        Ok(pushed != Push::Stored)
    }

    /// Counts the last [`tick`](Self::tick), whose work ended at `end`, into `links`'
    /// counters: one store for the count, one more only when a maximum grew. The period is
    /// the difference of the two last ticks' starts in the ring's time (ns, computed by
    /// [`tick`](Self::tick) for the ring's records), so a tick reads the difference of two
    /// instants twice, not three times. Nothing is counted before the first tick.
    pub fn account(&mut self, links: &Links, end: Instant) {
        let Some(start) = self.start else {
            return;
        };
        self.ticks += 1;
        links.ticks.store(self.ticks, Ordering::Relaxed);
        if let Some(last) = self.last_start_ns {
            let period = self.start_ns.saturating_sub(last);
            if period > self.max_period_ns {
                self.max_period_ns = period;
                links.max_period_ns.store(period, Ordering::Relaxed);
            }
        }
        let work = end.saturating_duration_since(start);
        if work > self.max_tick {
            self.max_tick = work;
            links
                .max_tick_ns
                .store(work.as_nanos() as u64, Ordering::Relaxed);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tandem_realtime::PerRobot;

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
    fn pop_into_overwrites_every_field_of_a_reused_command() {
        let ring = CommandRing::new(3, 4);
        let at = |t: u64| ring.base + Duration::from_micros(t);
        // A buffer of another robot count, with every flag set: the first pop makes it the
        // ring's three robots.
        let mut buf = Command::idle(5);
        buf.active = true;
        buf.finished = true;
        buf.fault = true;
        buf.tick = 99;
        assert_eq!(ring.pop_into(&mut buf), None);
        assert_eq!(
            (buf.tick, buf.ref_time.len()),
            (99, 5),
            "an empty ring leaves it"
        );
        // Tick 3: fault, robot 3 not needing the operator; tick 4: the other way round.
        for t in [3, 4] {
            assert!(ring.push(&cmd(t, 3), at(t)));
        }
        for t in [3, 4] {
            assert_eq!(ring.pop_into(&mut buf), Some(at(t)));
            assert_eq!(buf, cmd(t, 3), "tick {t}");
        }
        assert_eq!(ring.pop_into(&mut buf), None);
        assert_eq!(buf, cmd(4, 3));
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
    fn each_record_announces_the_next_deadline_and_a_half_full_ring_asks_for_a_wake() {
        let ring = CommandRing::new(2, 4);
        let ms = |t: u64| ring.base + Duration::from_millis(t);
        let push = |t: u64| {
            let c = cmd(t, 2);
            let words = (t, c.flags_word(), ring.since(ms(t)), ring.since(ms(t + 1)));
            ring.push_words(words, &c.ref_time, &c.speed)
        };
        assert_eq!(ring.next_deadline(), None);
        // 0 and 1 unread before the push: stored; 2 and 3 (half of 4 and more): a wake; full.
        let got: Vec<Push> = (1..=5).map(push).collect();
        use Push::{Dropped, Stored, Wake};
        assert_eq!(got, [Stored, Stored, Wake, Wake, Dropped]);
        assert_eq!(ring.dropped(), 1);
        assert_eq!(ring.pop().map(|(c, at)| (c.tick, at)), Some((1, ms(1))));
        assert_eq!(ring.next_deadline(), Some(ms(2)));
        for t in [2, 3] {
            assert_eq!(ring.pop().map(|(c, _)| c.tick), Some(t));
        }
        assert_eq!(ring.next_deadline(), Some(ms(4)));
        // One unread (4): stored; then two unread: a wake, with no deadline announced.
        assert_eq!(push(6), Stored);
        assert!(ring.push(&cmd(7, 2), ms(7)));
        assert_eq!(ring.dropped(), 1);
        let popped: Vec<(u64, Option<Instant>)> =
            std::iter::from_fn(|| ring.pop().map(|(c, _)| (c.tick, ring.next_deadline())))
                .collect();
        assert_eq!(popped, [(4, Some(ms(5))), (6, Some(ms(7))), (7, None)]);
        // `push_until` announces its deadline.
        assert!(ring.push_until(&cmd(8, 2), ms(8), ms(9)));
        assert_eq!(ring.pop().map(|(c, _)| c), Some(cmd(8, 2)));
        assert_eq!(ring.next_deadline(), Some(ms(9)));
    }

    #[test]
    fn the_writer_sleeps_to_the_lead_then_past_the_deadline_then_backs_off() {
        let s = WriterSchedule::NODE;
        let t0 = Instant::now();
        let us = Duration::from_micros;
        let d = Some(t0 + us(1_000));
        // Nothing announced: the poll; 1 ms ahead: to 200 µs before it; 3 ms: the poll.
        assert_eq!(s.sleep(t0, None, 0), us(1_000));
        assert_eq!(s.sleep(t0, d, 0), us(800));
        assert_eq!(s.sleep(t0, Some(t0 + us(3_000)), 0), us(1_000));
        // Within the lead: to 20 µs past the deadline.
        assert_eq!(s.sleep(t0 + us(800), d, 0), us(220));
        assert_eq!(s.sleep(t0 + us(1_010), d, 0), us(10));
        // Late from 20 µs past it on: 20 µs, doubled at each late pass, at most the poll.
        assert!(!s.is_late(t0 + us(1_019), d));
        assert!(s.is_late(t0 + us(1_020), d));
        assert!(!s.is_late(t0 + us(9_000), None));
        let backoff: Vec<u128> = (0..8)
            .map(|k| s.sleep(t0 + us(1_030), d, k).as_micros())
            .collect();
        assert_eq!(backoff, [20, 40, 80, 160, 320, 640, 1_000, 1_000]);
        assert_eq!(s.sleep(t0 + us(1_030), d, u32::MAX), us(1_000));
        // A tick shorter than the lead: straight to past the deadline.
        assert_eq!(s.sleep(t0, Some(t0 + us(100)), 0), us(120));
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
