//! The simulator behind `--port sim` and the harness's tests: the model served on one
//! end of a pseudo-terminal pair by a thread of the harness, telling the harness how
//! late it was and when it received and wrote (its lateness is the harness's own).

use super::{serve_with, UNWATCHED_US};
use crate::line::clock::PeerHeard;
use hiperface_model::datalink::RxChar;
use hiperface_model::{Profile, Slave, UartSettings};
use hiperface_suite::serve::{Hooks, Plain, Planned, Serving, Session};
use hiperface_suite::world::World;
use serialport::SerialPort;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// The simulator behind `--port sim`: the model as it is, telling the harness how
/// late it was (a read of the line overdue, a reply written after it was due), the
/// largest since the harness last took it. The harness adds it to its own lateness:
/// what a busy machine did to its own encoder is never the encoder's (a late reply
/// that lateness explains is UNKNOWN, and its case is run again).
struct Punctuality {
    late_us: Arc<AtomicU64>,
    /// The stamp of the latest character it received, and when the first run of its
    /// latest reply was written, µs on its clock: the harness compares them with when
    /// it wrote that character and read that reply ([`PeerHeard`]).
    heard: PeerHeard,
    /// The reply being written has had its first run written.
    writing_reply: bool,
}

impl Hooks for Punctuality {
    fn received(&mut self, ch: RxChar, _listening: Option<UartSettings>) -> bool {
        self.heard.last_us.fetch_max(ch.at_us, Ordering::SeqCst);
        true
    }
    fn read(&mut self, unwatched_us: u64) {
        self.late_us.fetch_max(unwatched_us, Ordering::SeqCst);
    }
    fn writing(&mut self, late_us: u64) {
        if late_us >= UNWATCHED_US {
            self.late_us.fetch_max(late_us, Ordering::SeqCst);
        }
        if !self.writing_reply {
            // Its first run is about to go out: written no earlier than now.
            let now = self.heard.epoch.elapsed().as_micros() as u64;
            self.heard.wrote_us.store(now.max(1), Ordering::SeqCst);
            self.writing_reply = true;
        }
    }
    fn sent(&mut self, _planned: &Planned, _end_us: u64) {
        self.writing_reply = false;
    }
}

/// A pseudo-terminal pair with the simulator on one end, served by a thread until
/// dropped.
pub struct PtySimulator {
    pub path: String,
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<std::io::Result<()>>>,
    /// How late the simulator was since the harness last took it, µs (see
    /// [`PtySimulator::lateness`]).
    late_us: Arc<AtomicU64>,
    /// When it received the latest character and wrote its latest reply, where it
    /// says so (see [`PtySimulator::heard`]).
    heard: Option<PeerHeard>,
}

impl PtySimulator {
    /// Start; returns the simulator and the other end of the pair, for the harness.
    pub fn start(profile: Profile) -> Result<(PtySimulator, Box<dyn SerialPort>), String> {
        PtySimulator::start_in(profile, World::default())
    }

    /// Start, the data rate of the line being whatever the other end of the
    /// pseudo-terminal sets (a serial device server that takes settings through RFC
    /// 2217): see [`Serving::follows_line_settings`].
    pub fn start_following_line_settings(profile: Profile) -> Result<(PtySimulator, Box<dyn SerialPort>), String> {
        PtySimulator::serving(Arc::default(), None, move |port, stop| {
            // The line's settings are the other end's.
            let serving = Serving { sets_port: false, follows_line_settings: true, ..Serving::MODEL };
            serve_with(
                port,
                &mut Session::new(Slave::operational(profile), Plain),
                serving,
                Instant::now(),
                &stop,
                None,
            )
        })
    }

    /// Start in a given world (inputs, start-up faults).
    pub fn start_in(profile: Profile, world: World) -> Result<(PtySimulator, Box<dyn SerialPort>), String> {
        let late_us = Arc::new(AtomicU64::new(0));
        let heard = PeerHeard { epoch: Instant::now(), last_us: Arc::default(), wrote_us: Arc::default() };
        let hooks = Punctuality { late_us: late_us.clone(), heard: heard.clone(), writing_reply: false };
        let epoch = heard.epoch;
        PtySimulator::serving(late_us, Some(heard), move |port, stop| {
            let mut slave = Slave::operational(profile);
            world.apply(&mut slave);
            serve_with(port, &mut Session::new(slave, hooks), Serving::MODEL, epoch, &stop, None)
        })
    }

    /// When the simulator received the latest character, where it says so (the one
    /// [`PtySimulator::start_in`] starts): a line to it takes how long after it wrote
    /// a character the simulator got it as the harness's own lateness
    /// ([`crate::line::serial::SerialLine::with_peer_lateness`]).
    pub fn heard(&self) -> Option<PeerHeard> {
        self.heard.clone()
    }

    /// How late the simulator was (a read of the line overdue, a reply written after
    /// it was due), the largest since it was last taken: a line to it adds this to the
    /// harness's own lateness ([`crate::line::serial::SerialLine::with_peer_lateness`]).
    pub fn lateness(&self) -> Arc<AtomicU64> {
        self.late_us.clone()
    }

    /// A pseudo-terminal pair, `serve` run on one end by a thread until the stop flag it
    /// is given is set; the other end for the harness. `late_us`: where `serve` reports
    /// how late it was (see [`PtySimulator::lateness`]); `heard`: where it says when it
    /// received and wrote, if it does (see [`PtySimulator::heard`]).
    fn serving(
        late_us: Arc<AtomicU64>,
        heard: Option<PeerHeard>,
        serve: impl FnOnce(Box<dyn SerialPort>, Arc<AtomicBool>) -> std::io::Result<()> + Send + 'static,
    ) -> Result<(PtySimulator, Box<dyn SerialPort>), String> {
        let (sim_end, harness_end) =
            crate::line::pty_pair().map_err(|e| format!("cannot create a pseudo-terminal pair: {e}"))?;
        let path = harness_end.name().unwrap_or_else(|| "pty".into());
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let thread = std::thread::spawn(move || serve(Box::new(sim_end), flag));
        Ok((PtySimulator { path, stop, thread: Some(thread), late_us, heard }, Box::new(harness_end)))
    }
}

impl Drop for PtySimulator {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
