//! The output pipeline of `hydrocyl simulate`: the solve hands over blocks
//! of output rows (raw states, or channels); each block becomes a piece of
//! CSV text (its probes read on a circuit of the thread's own, checked,
//! formatted) on whichever thread is free — the writer thread, or the
//! solve's while the writer is behind and once the solve has ended — and the
//! writer thread writes the pieces in order. So both cores work to the last
//! row, and the bytes are those of one thread formatting every block in
//! turn (a piece depends on its block alone).

use crate::error::CliError;
use crate::output::{OutputId, Outputs};
use hydrocyl_system::run::{DeepCavitation, ProbeReader, Run, Solver};
use std::collections::{BTreeMap, VecDeque};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};

/// The writer thread writes the text it holds once it is this many bytes
/// (more than the output's buffer, [`crate::output`]: written past it, not
/// copied into it).
const WRITE_AT: usize = 1 << 17;

/// Blocks waiting for a thread at most: the memory stays that of this many
/// blocks (a few MB) whatever the record's length. Beyond it the solve's
/// thread makes blocks itself (`--probes-behind`).
pub const QUEUE: usize = 256;

/// One block of a run's output: its times and either its channels (one
/// column after the other, `time.len()` each, [`Rows::Channels`]) or its
/// full states (row-major, [`Rows::States`]).
#[derive(Default)]
pub struct Block {
    /// Output times \[s\].
    pub time: Vec<f64>,
    /// Channels or states (see the type's doc).
    pub values: Vec<f64>,
}

/// What the blocks hold and how they become rows.
pub enum Rows {
    /// Channels, already checked by the solve; the CSV header.
    Channels(Vec<u8>),
    /// Raw states: each thread reads the probes on a circuit of its own
    /// (made by [`Maker::states`]), checks the solution and makes the header
    /// from the first block.
    States {
        /// The method, for the remedy of an unstable solution.
        solver: Solver,
        /// rk4's step, for the same.
        rk4_step: f64,
    },
}

/// What turns blocks into text on one thread: a probe reader of its own
/// ([`Rows::States`]) and the buffers it reuses.
#[derive(Default)]
pub struct Maker {
    reader: Option<ProbeReader>,
    run: Run,
}

impl Maker {
    /// A maker of [`Rows::States`] pieces reading the probes with `reader`.
    pub fn states(reader: ProbeReader) -> Self {
        Maker {
            reader: Some(reader),
            run: Run::default(),
        }
    }

    /// Appends block `seq`'s rows to `out` (the header first for block 0);
    /// what it read of the chamber pressures.
    fn piece(
        &mut self,
        rows: &Rows,
        seq: usize,
        block: &Block,
        out: &mut Vec<u8>,
    ) -> Result<Lows, CliError> {
        let n = block.time.len().max(1);
        match (rows, self.reader.as_mut()) {
            (Rows::Channels(header), _) => {
                if seq == 0 {
                    out.extend_from_slice(header);
                }
                let columns: Vec<&[f64]> = std::iter::once(block.time.as_slice())
                    .chain(block.values.chunks_exact(n))
                    .collect();
                hydrocyl_identify::plaincsv::append_rows(&columns, out);
                Ok(Lows::default())
            }
            (Rows::States { solver, rk4_step }, Some(r)) => {
                let run = &mut self.run;
                r.read_channels(&block.time, &block.values, run);
                let deep = crate::simulate::check_solution(run, *solver, *rk4_step)?;
                for c in &mut run.channels {
                    crate::simulate::flush_to_zero(&mut c.values);
                }
                if seq == 0 {
                    out.extend_from_slice(
                        crate::simulate::column_headers(&run.channels)
                            .join(",")
                            .as_bytes(),
                    );
                    out.push(b'\n');
                }
                let columns: Vec<&[f64]> = std::iter::once(&run.time)
                    .chain(run.channels.iter().map(|c| &c.values))
                    .map(Vec::as_slice)
                    .collect();
                hydrocyl_identify::plaincsv::append_rows(&columns, out);
                Ok(Lows {
                    min_p: run.min_chamber_pressure(),
                    deep,
                })
            }
            (Rows::States { .. }, None) => Err(CliError::Input(
                "the output's probes have no reader on this thread".into(),
            )),
        }
    }
}

/// What the blocks of a run read of its chamber pressures, merged in any
/// order: the lowest \[Pa\] (infinite when none was read) and where the
/// constant-B liquid left its range ([`DeepCavitation`], warned of once
/// the whole run has passed its checks).
#[derive(Clone, Debug)]
pub struct Lows {
    /// The lowest chamber pressure \[Pa\].
    pub min_p: f64,
    /// A chamber far below vacuum.
    pub deep: Option<DeepCavitation>,
}

impl Default for Lows {
    fn default() -> Self {
        Lows {
            min_p: f64::INFINITY,
            deep: None,
        }
    }
}

impl Lows {
    /// Adds those of another block.
    pub fn add(&mut self, other: Lows) {
        self.min_p = self.min_p.min(other.min_p);
        self.deep = DeepCavitation::merged(self.deep.take(), other.deep);
    }
}

/// The blocks not yet taken by a thread.
#[derive(Default)]
struct Work {
    queue: VecDeque<(usize, Block)>,
    /// Blocks handed over so far (the next block's number).
    pushed: usize,
    /// No more blocks will come.
    closed: bool,
    /// A thread failed: nothing more is taken or handed over.
    stopped: bool,
    /// Blocks done with, for reuse.
    free: Vec<Block>,
}

/// The pieces made and not yet written, and what went wrong.
struct Sink {
    ready: BTreeMap<usize, Vec<u8>>,
    /// The first failure, by block number (the earliest rows').
    error: Option<(usize, CliError)>,
    lows: Lows,
    /// Texts written, for reuse.
    free: Vec<Vec<u8>>,
}

struct Shared {
    /// Set before the first block is handed over ([`Writer::rows`]).
    rows: std::sync::OnceLock<Rows>,
    work: Mutex<Work>,
    /// Signalled when a block is queued or taken, or the work closes or stops.
    work_cv: Cv,
    sink: Mutex<Sink>,
    /// Signalled when a piece is ready or a thread fails.
    sink_cv: Cv,
}

/// A lock that survives a panicking holder (whose error is then reported
/// by the join).
fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// A condition variable that counts its waiters, so that a notification
/// nobody waits for is skipped: std's `notify_all` makes a system call
/// every time (three per block, ~120 a 10 s run, most with no one
/// waiting). A waiter is counted while it holds the state's lock, before
/// it sleeps; a notifier changes the state under that lock and reads the
/// count after: it sees every waiter that could have missed the change.
#[derive(Default)]
struct Cv {
    cv: Condvar,
    waiters: AtomicUsize,
}

impl Cv {
    /// Sleeps until notified (or spuriously woken), the lock of `g`
    /// released meanwhile.
    fn wait<'a, T>(&self, g: MutexGuard<'a, T>) -> MutexGuard<'a, T> {
        self.waiters.fetch_add(1, Ordering::SeqCst);
        let g = self
            .cv
            .wait(g)
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        self.waiters.fetch_sub(1, Ordering::SeqCst);
        g
    }

    /// Wakes every waiter, if there is one.
    fn notify_all(&self) {
        if self.waiters.load(Ordering::SeqCst) > 0 {
            self.cv.notify_all();
        }
    }
}

impl Shared {
    /// Records the failure of block `seq` (the earliest is kept) and stops
    /// the work.
    fn fail(&self, seq: usize, e: CliError) {
        {
            let mut s = lock(&self.sink);
            if s.error.as_ref().is_none_or(|(k, _)| seq < *k) {
                s.error = Some((seq, e));
            }
        }
        lock(&self.work).stopped = true;
        self.work_cv.notify_all();
        self.sink_cv.notify_all();
    }

    /// The next block, waiting for one while `wait` and the work is open;
    /// `None` when there is none (closed, stopped, or empty and not `wait`).
    fn take(&self, wait: bool) -> Option<(usize, Block)> {
        let mut w = lock(&self.work);
        loop {
            if w.stopped {
                return None;
            }
            if let Some(job) = w.queue.pop_front() {
                drop(w);
                self.work_cv.notify_all();
                return Some(job);
            }
            if w.closed || !wait {
                return None;
            }
            w = self.work_cv.wait(w);
        }
    }

    /// Makes block `seq`'s piece with `maker` and hands it to the sink, the
    /// block back for reuse.
    fn make(&self, maker: &mut Maker, seq: usize, block: Block) {
        let mut text = lock(&self.sink).free.pop().unwrap_or_default();
        text.clear();
        let r = match self.rows.get() {
            Some(rows) => maker.piece(rows, seq, &block, &mut text),
            None => Err(CliError::Input("the output's rows are not set".into())),
        };
        lock(&self.work).free.push(block);
        match r {
            Ok(p) => {
                {
                    let mut s = lock(&self.sink);
                    s.lows.add(p);
                    s.ready.insert(seq, text);
                }
                self.sink_cv.notify_all();
            }
            Err(e) => self.fail(seq, e),
        }
    }
}

/// What the writer thread hands back: the outputs and its first error.
type Written = (Outputs, Result<(), CliError>);

/// The pipeline (see the module doc): the writer thread and what it shares
/// with the solve's thread.
pub struct Writer {
    shared: Arc<Shared>,
    /// The thread's outputs and result, sent as its last act (its exit is
    /// not waited for); `None` once received.
    written: Option<std::sync::mpsc::Receiver<Written>>,
}

impl Writer {
    /// Starts the writer thread on `outputs` (file `id`), which it hands
    /// back at [`Writer::finish`]; its [`Maker`] is made there by `maker`
    /// (a circuit stays on the thread that built it) while the solve's
    /// thread builds its own. What the blocks hold is said before the first
    /// is handed over ([`Writer::rows`]).
    pub fn start(
        mut outputs: Outputs,
        id: OutputId,
        maker: Box<dyn FnOnce() -> Result<Maker, CliError> + Send>,
    ) -> Self {
        let shared = Arc::new(Shared {
            rows: std::sync::OnceLock::new(),
            work: Mutex::new(Work::default()),
            work_cv: Cv::default(),
            sink: Mutex::new(Sink {
                ready: BTreeMap::new(),
                error: None,
                lows: Lows::default(),
                free: Vec::new(),
            }),
            sink_cv: Cv::default(),
        });
        let sh = shared.clone();
        let (send, written) = std::sync::mpsc::channel::<Written>();
        std::thread::spawn(move || {
            let mut maker = match maker() {
                Ok(m) => Some(m),
                Err(e) => {
                    sh.fail(0, e);
                    None
                }
            };
            crate::progress::mark("writer: ready");
            // the next block to write, and the pieces in order not yet written
            let mut next = 0usize;
            let mut pending: Vec<Vec<u8>> = Vec::new();
            loop {
                let job = match maker.as_mut() {
                    Some(_) => sh.take(true),
                    None => None,
                };
                if let (Some((seq, block)), Some(m)) = (job, maker.as_mut()) {
                    sh.make(m, seq, block);
                } else {
                    // no more blocks to take: wait for the pieces the solve's
                    // thread is still making
                    let w = lock(&sh.work);
                    let (stopped, total) = (w.stopped, w.pushed);
                    drop(w);
                    if stopped {
                        break;
                    }
                    let mut s = lock(&sh.sink);
                    while next < total && s.error.is_none() && !s.ready.contains_key(&next) {
                        s = sh.sink_cv.wait(s);
                    }
                    if s.error.is_some() {
                        break;
                    }
                    if next == total {
                        break;
                    }
                }
                {
                    let mut s = lock(&sh.sink);
                    while let Some(p) = s.ready.remove(&next) {
                        pending.push(p);
                        next += 1;
                    }
                }
                if pending.iter().map(Vec::len).sum::<usize>() >= WRITE_AT {
                    if let Err(e) = outputs.write_all(id, &pending) {
                        sh.fail(next, e);
                        break;
                    }
                    lock(&sh.sink).free.append(&mut pending);
                }
            }
            crate::progress::mark("writer: last block made");
            let result = if lock(&sh.sink).error.is_none() {
                outputs.write_all(id, &pending)
            } else {
                Ok(())
            };
            crate::progress::mark("writer: done");
            let _ = send.send((outputs, result));
        });
        Writer {
            shared,
            written: Some(written),
        }
    }

    /// Says what the blocks hold (once, before the first is handed over).
    pub fn rows(&self, rows: Rows) {
        let _ = self.shared.rows.set(rows);
    }

    /// Whether [`Writer::rows`] was said.
    pub fn has_rows(&self) -> bool {
        self.shared.rows.get().is_some()
    }

    /// Blocks handed over and not yet taken by a thread.
    pub fn behind(&self) -> usize {
        lock(&self.shared.work).queue.len()
    }

    /// A block for `fill` to fill: a reused one, emptied.
    fn block(&self, fill: impl FnOnce(&mut Block)) -> Block {
        let mut block = lock(&self.shared.work).free.pop().unwrap_or_default();
        block.time.clear();
        block.values.clear();
        fill(&mut block);
        block
    }

    /// Hands over a block filled by `fill` (waiting while [`QUEUE`] wait);
    /// an error when the work has stopped (a failed write or a bad
    /// solution, which [`Writer::finish`] reports).
    pub fn push(&self, fill: impl FnOnce(&mut Block)) -> Result<(), CliError> {
        let block = self.block(fill);
        let mut w = lock(&self.shared.work);
        while w.queue.len() >= QUEUE && !w.stopped {
            w = self.shared.work_cv.wait(w);
        }
        if w.stopped {
            return Err(CliError::Input("the output writer stopped".into()));
        }
        let seq = w.pushed;
        w.pushed += 1;
        w.queue.push_back((seq, block));
        drop(w);
        self.shared.work_cv.notify_all();
        Ok(())
    }

    /// Makes a block filled by `fill` into its piece here, with `maker`
    /// (the solve's thread, while the writer is behind); an error when the
    /// work has stopped.
    pub fn make_here(
        &self,
        maker: &mut Maker,
        fill: impl FnOnce(&mut Block),
    ) -> Result<(), CliError> {
        let block = self.block(fill);
        let seq = {
            let mut w = lock(&self.shared.work);
            if w.stopped {
                return Err(CliError::Input("the output writer stopped".into()));
            }
            w.pushed += 1;
            w.pushed - 1
        };
        self.shared.make(maker, seq, block);
        Ok(())
    }

    /// Closes the work, makes the blocks still waiting together with the
    /// writer thread (with `own`, made by `build` when first needed), and
    /// waits for the thread to write them all: the outputs back and what
    /// was read of the chamber pressures ([`Lows`]), or the first error
    /// (the earliest rows').
    pub fn finish(
        mut self,
        own: &mut Option<Maker>,
        build: &mut dyn FnMut() -> Result<Maker, CliError>,
    ) -> Result<(Outputs, Lows), CliError> {
        lock(&self.shared.work).closed = true;
        self.shared.work_cv.notify_all();
        crate::progress::mark("solve's thread: helping");
        while let Some((seq, block)) = self.shared.take(false) {
            if own.is_none() {
                match build() {
                    Ok(m) => *own = Some(m),
                    Err(e) => {
                        self.shared.fail(seq, e);
                        break;
                    }
                }
            }
            if let Some(m) = own.as_mut() {
                self.shared.make(m, seq, block);
            }
        }
        crate::progress::mark("solve's thread: done helping");
        let written = self
            .written
            .take()
            .ok_or_else(|| CliError::Input("no writer".into()))?
            .recv();
        let error = lock(&self.shared.sink).error.take();
        match (written, error) {
            (Ok(_), Some((_, e))) => Err(e),
            (Ok((_, Err(e))), None) => Err(e),
            (Ok((outputs, Ok(()))), None) => {
                Ok((outputs, std::mem::take(&mut lock(&self.shared.sink).lows)))
            }
            (Err(_), _) => Err(CliError::Input("the output writer failed".into())),
        }
    }
}

impl Drop for Writer {
    /// A writer not finished (the run failed first) stops its thread and
    /// takes the outputs back, so that they are dropped (their temporaries
    /// removed) before the process ends.
    fn drop(&mut self) {
        if let Some(written) = self.written.take() {
            self.shared.fail(
                usize::MAX,
                CliError::Input("the run stopped before its end".into()),
            );
            drop(written.recv());
        }
    }
}
