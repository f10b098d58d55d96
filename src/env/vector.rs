//! [`VecEnv`]: N environments stepped on a small pool of worker threads — all at once
//! ([`VecEnv::step`]), or envpool-style ([`VecEnv::send`] / [`VecEnv::recv`]), which returns
//! whichever environments finish first: macro actions differ widely in duration.
//!
//! Environment `i` belongs to worker `i mod threads`, which runs its actions in the order they
//! were sent, one at a time; its results depend only on its own resets and actions, so
//! sub-environment `i` gives bit for bit what a single [`MacroEnv`] given the same resets and
//! actions gives. A synchronous [`VecEnv::step`] runs worker 0's share on the calling thread,
//! so two environments on two cores need one hand-off, not two; workers and the waiting caller
//! spin for up to [`SPIN_WAIT`] before they sleep, so a policy loop's next batch finds them
//! awake (a sleeping thread takes tens of microseconds to wake, a `ctrl` step about 100).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender, TryRecvError, channel};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::{Action, EnvConfig, MacroEnv, Observation, Reset, StepResult};
use crate::error::Error;
use crate::plan::Plan;
use crate::sim::Scene;

/// Most environments in one [`VecEnv`].
pub const MAX_ENVS: usize = 1024;

/// How long a worker with nothing to do, or a caller waiting for results, polls before it
/// sleeps: long enough to span a policy loop's Python between two batches with room to spare (a
/// `ctrl` step is about 100 µs; docs/python.md has the settings measured). The price: an idle
/// worker burns up to this much CPU after each step.
pub const SPIN_WAIT: Duration = Duration::from_micros(500);

/// How often a waiting caller asks its interrupt poll (Ctrl-C) whether to stop.
pub const INTERRUPT_POLL: Duration = Duration::from_millis(20);

/// A step to run: the environment and its action.
type Job = (usize, Action);
/// A finished step: the environment's id and its result.
pub type Finished = (usize, Result<StepResult, Error>);

/// N environments of one scene (and tree and config) on worker threads (see the module docs).
pub struct VecEnv {
    envs: Vec<Arc<Mutex<MacroEnv>>>,
    /// Each worker's job queue (empty once dropping).
    jobs: Vec<Sender<Job>>,
    done: Receiver<Finished>,
    workers: Vec<JoinHandle<()>>,
    busy: Vec<bool>,
    pending: usize,
    /// Set while an interrupt stops the running steps (each stops at its next control period).
    cancel: Arc<AtomicBool>,
    /// A step of this vector environment was interrupted: every environment must be reset.
    interrupted: bool,
}

fn lock(env: &Mutex<MacroEnv>) -> MutexGuard<'_, MacroEnv> {
    env.lock().unwrap_or_else(|e| e.into_inner())
}

fn invalid(message: String) -> Error {
    Error::Action { message }
}

impl VecEnv {
    /// `n` environments (1 … [`MAX_ENVS`]) like [`MacroEnv::new`]'s, stepped on
    /// min(`n`, cores) worker threads.
    ///
    /// # Errors
    /// As [`MacroEnv::new`]; [`Error::Config`] for `n` out of range.
    pub fn new(
        app: &crate::App,
        scene: Scene,
        tree: Option<Arc<Plan>>,
        config: EnvConfig,
        n: usize,
    ) -> Result<Self, Error> {
        let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
        Self::with_threads(app, scene, tree, config, n, cores)
    }

    /// Like [`new`](Self::new), on min(`n`, `threads`) worker threads (at least one).
    ///
    /// # Errors
    /// As [`new`](Self::new).
    pub fn with_threads(
        app: &crate::App,
        scene: Scene,
        tree: Option<Arc<Plan>>,
        config: EnvConfig,
        n: usize,
        threads: usize,
    ) -> Result<Self, Error> {
        if !(1..=MAX_ENVS).contains(&n) {
            return Err(Error::Config {
                message: format!("a vector environment holds 1 … {MAX_ENVS} environments, not {n}"),
            });
        }
        super::memory::check_fits(n, super::memory::available_memory())?;
        let mut envs = Vec::with_capacity(n);
        for _ in 0..n {
            let env = MacroEnv::new(app, scene.clone(), tree.clone(), config.clone())?;
            envs.push(Arc::new(Mutex::new(env)));
        }
        let (done_tx, done) = channel::<Finished>();
        let cancel = Arc::new(AtomicBool::new(false));
        let mut jobs = Vec::new();
        let mut workers = Vec::new();
        for k in 0..threads.clamp(1, n) {
            let (tx, queue) = channel::<Job>();
            let done_tx = done_tx.clone();
            let envs = envs.clone();
            let cancel = cancel.clone();
            let handle = std::thread::Builder::new()
                .name(format!("macrotree-env-{k}"))
                .spawn(move || worker(&queue, &envs, &done_tx, &cancel))
                .map_err(|e| Error::Simulator {
                    message: format!("cannot start a worker thread: {e}"),
                })?;
            jobs.push(tx);
            workers.push(handle);
        }
        Ok(Self {
            envs,
            jobs,
            done,
            workers,
            busy: vec![false; n],
            pending: 0,
            cancel,
            interrupted: false,
        })
    }

    /// Number of environments.
    pub fn num_envs(&self) -> usize {
        self.envs.len()
    }

    /// Number of worker threads.
    pub fn threads(&self) -> usize {
        self.workers.len()
    }

    /// Steps sent and not yet received.
    pub fn pending(&self) -> usize {
        self.pending
    }

    fn idle(&self, i: usize) -> Result<(), Error> {
        if i >= self.envs.len() {
            return Err(invalid(format!(
                "environment {i} does not exist; there are {} (0 … {})",
                self.envs.len(),
                self.envs.len() - 1
            )));
        }
        if self.busy[i] {
            return Err(invalid(format!(
                "environment {i} is still running a step; receive it first (recv)"
            )));
        }
        Ok(())
    }

    /// Resets every environment, `how[i]` for environment `i`, on the calling thread.
    ///
    /// # Errors
    /// [`Error::Action`] when `how` does not hold one reset per environment, a step is still
    /// running, or a reset is refused (the first such error).
    pub fn reset(&mut self, how: &[Reset]) -> Result<Vec<Observation>, Error> {
        if how.len() != self.envs.len() {
            return Err(invalid(format!(
                "reset got {} resets for {} environments",
                how.len(),
                self.envs.len()
            )));
        }
        let ids: Vec<usize> = (0..how.len()).collect();
        self.reset_each(&ids, how)
    }

    /// Resets environments `ids` (`how[k]` for `ids[k]`), leaving the others as they are.
    ///
    /// # Errors
    /// As [`reset`](Self::reset), for unknown or repeated ids too.
    pub fn reset_each(&mut self, ids: &[usize], how: &[Reset]) -> Result<Vec<Observation>, Error> {
        self.check_ids(ids, how.len())?;
        let obs = ids
            .iter()
            .zip(how)
            .map(|(&i, h)| lock(&self.envs[i]).reset(h))
            .collect::<Result<Vec<_>, Error>>()?;
        if ids.len() == self.envs.len() {
            self.interrupted = false;
        }
        Ok(obs)
    }

    fn check_ids(&self, ids: &[usize], n: usize) -> Result<(), Error> {
        if ids.len() != n {
            return Err(invalid(format!(
                "{} environment ids for {n} actions or resets",
                ids.len()
            )));
        }
        let mut seen = vec![false; self.envs.len()];
        for &i in ids {
            self.idle(i)?;
            if std::mem::replace(&mut seen[i], true) {
                return Err(invalid(format!("environment {i} is given twice")));
            }
        }
        Ok(())
    }

    /// Checks every action of a batch before any environment moves ([`MacroEnv::check_action`]),
    /// so an invalid one refuses the whole batch and leaves every environment as it was.
    fn check_actions(&self, ids: &[usize], actions: &[Action]) -> Result<(), Error> {
        if self.interrupted {
            return Err(invalid(
                "a step of this vector environment was interrupted; reset every environment".to_string(),
            ));
        }
        for (&i, a) in ids.iter().zip(actions) {
            lock(&self.envs[i]).check_action(a).map_err(|e| match e {
                Error::Action { message } => invalid(format!(
                    "environment {i}: {message} (no environment of the batch was stepped)"
                )),
                other => other,
            })?;
        }
        Ok(())
    }

    /// Steps every environment, `actions[i]` on environment `i`, in parallel; the results in
    /// environment order.
    ///
    /// # Errors
    /// [`Error::Action`] when `actions` does not hold one action per environment or steps sent
    /// with [`send`](Self::send) are still pending. Each environment's own result may be an
    /// error (invalid action) as [`MacroEnv::step`]'s.
    pub fn step(&mut self, actions: &[Action]) -> Result<Vec<Result<StepResult, Error>>, Error> {
        let ids: Vec<usize> = (0..self.envs.len()).collect();
        self.step_each(&ids, actions)
    }

    /// Steps environments `ids` (`actions[k]` on `ids[k]`) in parallel and waits for them: the
    /// share of worker 0 runs on the calling thread, the others' on their workers. The results
    /// in the order of `ids`.
    ///
    /// # Errors
    /// As [`step`](Self::step), and for unknown or repeated ids.
    pub fn step_each(
        &mut self,
        ids: &[usize],
        actions: &[Action],
    ) -> Result<Vec<Result<StepResult, Error>>, Error> {
        self.step_each_with(ids, actions, &mut || false)
    }

    /// [`step_each`](Self::step_each), asking `interrupt` about every [`INTERRUPT_POLL`] (and
    /// at every control period of this thread's own share) whether to stop: then every running
    /// step stops at its next control period, the call returns [`Error::Interrupted`], and every
    /// environment must be reset before the next step.
    ///
    /// # Errors
    /// As [`step_each`](Self::step_each); [`Error::Interrupted`] as above.
    pub fn step_each_with(
        &mut self,
        ids: &[usize],
        actions: &[Action],
        interrupt: &mut dyn FnMut() -> bool,
    ) -> Result<Vec<Result<StepResult, Error>>, Error> {
        if self.pending > 0 {
            return Err(invalid(format!(
                "{} steps sent with send() are still pending; receive them first (recv)",
                self.pending
            )));
        }
        self.check_ids(ids, actions.len())?;
        self.check_actions(ids, actions)?;
        let threads = self.jobs.len();
        let (mine, theirs): (Vec<usize>, Vec<usize>) =
            (0..ids.len()).partition(|&k| ids[k].is_multiple_of(threads));
        let their_ids: Vec<usize> = theirs.iter().map(|&k| ids[k]).collect();
        let their_actions: Vec<Action> = theirs.iter().map(|&k| actions[k].clone()).collect();
        self.send(&their_ids, &their_actions)?;
        let mut out: Vec<Option<Result<StepResult, Error>>> = (0..ids.len()).map(|_| None).collect();
        // Where environment `i`'s result goes in `out`.
        let mut slot = vec![None; self.envs.len()];
        for (k, &i) in ids.iter().enumerate() {
            slot[i] = Some(k);
        }
        let cancel = self.cancel.clone();
        let mut stop = || {
            cancel.load(Ordering::Relaxed) || {
                let asked = interrupt();
                if asked {
                    cancel.store(true, Ordering::Relaxed);
                }
                asked
            }
        };
        for k in mine {
            out[k] = Some(run_job(&self.envs, ids[k], &actions[k], &mut stop));
        }
        // The workers are busy with their share and this thread has nothing else to do: poll
        // for their results before sleeping.
        let mut left = their_ids.len();
        while left > 0 {
            let (i, r) = wait_polled(&self.done, true, &mut stop)
                .ok_or_else(|| invalid("the worker threads have stopped".to_string()))?;
            if let Some(k) = slot[i] {
                out[k] = Some(r);
            }
            self.busy[i] = false;
            self.pending -= 1;
            left -= 1;
        }
        self.end_interrupt()?;
        Ok(out
            .into_iter()
            .map(|r| r.unwrap_or_else(|| Err(invalid("a step result went missing".to_string()))))
            .collect())
    }

    /// Starts `actions[k]` on environment `ids[k]` and returns at once; collect the results
    /// with [`recv`](Self::recv).
    ///
    /// # Errors
    /// [`Error::Action`] for unknown or repeated ids, lengths that differ, an environment still
    /// running a step, or an invalid action (checked for the whole batch first: then nothing is
    /// sent).
    pub fn send(&mut self, ids: &[usize], actions: &[Action]) -> Result<(), Error> {
        self.check_ids(ids, actions.len())?;
        self.check_actions(ids, actions)?;
        for (&i, a) in ids.iter().zip(actions) {
            self.jobs[i % self.jobs.len()]
                .send((i, a.clone()))
                .map_err(|_| invalid("the worker threads have stopped".to_string()))?;
            self.busy[i] = true;
            self.pending += 1;
        }
        Ok(())
    }

    /// Waits until at least `min_batch` of the sent steps have finished and returns every
    /// finished one (environment id, result), in the order they finished.
    ///
    /// # Errors
    /// [`Error::Action`] when `min_batch` is 0 or more than the steps pending.
    pub fn recv(&mut self, min_batch: usize) -> Result<Vec<Finished>, Error> {
        self.recv_with(min_batch, &mut || false)
    }

    /// [`recv`](Self::recv), asking `interrupt` about every [`INTERRUPT_POLL`] whether to stop:
    /// then every pending step stops at its next control period, their results are dropped, the
    /// call returns [`Error::Interrupted`], and every environment must be reset.
    ///
    /// # Errors
    /// As [`recv`](Self::recv); [`Error::Interrupted`] as above.
    pub fn recv_with(
        &mut self,
        min_batch: usize,
        interrupt: &mut dyn FnMut() -> bool,
    ) -> Result<Vec<Finished>, Error> {
        if min_batch == 0 || min_batch > self.pending {
            return Err(invalid(format!(
                "recv({min_batch}): expected 1 … {} (the steps pending)",
                self.pending
            )));
        }
        let mut out = Vec::with_capacity(min_batch);
        let cancel = self.cancel.clone();
        let mut stop = || {
            let asked = interrupt();
            if asked {
                cancel.store(true, Ordering::Relaxed);
            }
            asked
        };
        while out.len() < min_batch && !self.cancel.load(Ordering::Relaxed) {
            // Sleep at once: while the workers run, this thread's core may be one they need.
            let d = wait_polled(&self.done, false, &mut stop)
                .ok_or_else(|| invalid("the worker threads have stopped".to_string()))?;
            out.push(d);
        }
        if self.cancel.load(Ordering::Relaxed) {
            // Every pending step stops at its next control period: collect them all.
            while out.len() < self.pending {
                let d = self
                    .done
                    .recv()
                    .map_err(|_| invalid("the worker threads have stopped".to_string()))?;
                out.push(d);
            }
            for (i, _) in &out {
                self.busy[*i] = false;
            }
            self.pending = 0;
            self.end_interrupt()?;
        }
        while let Ok(d) = self.done.try_recv() {
            out.push(d);
        }
        for (i, _) in &out {
            self.busy[*i] = false;
        }
        self.pending -= out.len();
        Ok(out)
    }

    /// After the steps of a call have all returned: if an interrupt stopped them, clears the
    /// stop, marks the vector environment for a reset and says so.
    fn end_interrupt(&mut self) -> Result<(), Error> {
        if !self.cancel.swap(false, Ordering::Relaxed) {
            return Ok(());
        }
        self.interrupted = true;
        Err(Error::Interrupted {
            message: "the vector environment's steps were interrupted; reset every environment".to_string(),
        })
    }

    /// The observation of environment `i` now.
    ///
    /// # Errors
    /// [`Error::Action`] for an unknown environment or one still running a step.
    pub fn observe(&self, i: usize) -> Result<Observation, Error> {
        self.idle(i)?;
        Ok(lock(&self.envs[i]).observe())
    }

    /// Runs `f` on environment `i` (on the calling thread: e.g. to render it).
    ///
    /// # Errors
    /// [`Error::Action`] for an unknown environment or one still running a step.
    pub fn with_env<T>(&self, i: usize, f: impl FnOnce(&mut MacroEnv) -> T) -> Result<T, Error> {
        self.idle(i)?;
        Ok(f(&mut lock(&self.envs[i])))
    }
}

impl Drop for VecEnv {
    fn drop(&mut self) {
        self.jobs.clear();
        for w in self.workers.drain(..) {
            let _ = w.join();
        }
    }
}

/// What polling a queue for up to [`SPIN_WAIT`] found: `Some` when it settled (a message, or
/// `None` once every sender is gone), `None` when nothing came in that time.
fn spin<T>(queue: &Receiver<T>) -> Option<Option<T>> {
    let start = Instant::now();
    while start.elapsed() < SPIN_WAIT {
        match queue.try_recv() {
            Ok(m) => return Some(Some(m)),
            Err(TryRecvError::Disconnected) => return Some(None),
            Err(TryRecvError::Empty) => std::hint::spin_loop(),
        }
    }
    None
}

/// The next message of `queue`: polled for up to [`SPIN_WAIT`], then waited for; `None` once
/// every sender is gone.
fn wait<T>(queue: &Receiver<T>) -> Option<T> {
    spin(queue).unwrap_or_else(|| queue.recv().ok())
}

/// [`wait`] (polling first only when `spin`), asking `stop` every [`INTERRUPT_POLL`] while it
/// sleeps (the message still comes: a stopped step answers at its next control period).
fn wait_polled<T>(queue: &Receiver<T>, spin_first: bool, stop: &mut dyn FnMut() -> bool) -> Option<T> {
    if spin_first && let Some(settled) = spin(queue) {
        return settled;
    }
    loop {
        match queue.recv_timeout(INTERRUPT_POLL) {
            Ok(m) => return Some(m),
            Err(RecvTimeoutError::Disconnected) => return None,
            Err(RecvTimeoutError::Timeout) => {
                stop();
            }
        }
    }
}

/// A worker: takes the next job of its queue, runs it on its environment (stopping at the next
/// control period once `cancel` is set), sends the result; stops when its queue closes.
fn worker(
    queue: &Receiver<Job>,
    envs: &[Arc<Mutex<MacroEnv>>],
    done: &Sender<Finished>,
    cancel: &AtomicBool,
) {
    while let Some((i, action)) = wait(queue) {
        let r = run_job(envs, i, &action, &mut || cancel.load(Ordering::Relaxed));
        if done.send((i, r)).is_err() {
            return;
        }
    }
}

/// Runs one step of environment `i`, asking `interrupt` at every control period; a panic
/// becomes an error result (never crosses threads or the FFI).
fn run_job(
    envs: &[Arc<Mutex<MacroEnv>>],
    i: usize,
    action: &Action,
    interrupt: &mut dyn FnMut() -> bool,
) -> Result<StepResult, Error> {
    catch_unwind(AssertUnwindSafe(|| lock(&envs[i]).step_with(action, interrupt))).unwrap_or_else(|panic| {
        let what = panic
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        tracing::error!(target: "macrotree::env", env = i, "a step panicked: {what}");
        Err(Error::Simulator {
            message: format!("environment {i}: the step panicked (a bug): {what}"),
        })
    })
}
