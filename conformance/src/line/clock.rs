//! Real time on a line: the clock, sleeping, bounded reads, receive stamps, and the
//! window in which a request written at once ended for the peer.
//!
//! Timing convention (see docs/src/design.md, "Timing on lines without a UART clock"):
//! a character's *stamp* is when the far end's UART would have completed it (the end
//! of its stop bit). On a real port the UART clocks the characters; a
//! pseudo-terminal or a TCP connection has no baud rate, so the harness writes a
//! request at once and knows its end only as a window (see [`write_whole`]), and
//! reads a peer's reply knowing that the peer may have meant a write as the start of
//! a character (a program writing its whole reply at once) or as its end (a program
//! playing the UART).

use hiperface_suite::line::rx_clock::RxClock;
use hiperface_suite::line::{LineError, Sent, Window};

/// The [`hiperface_suite::line::Line`] methods of a line in real time, answered by its
/// [`RealTime`] field: sleeping until a time, the jitter graded with, and the harness's
/// lateness.
macro_rules! real_time_methods {
    ($field:ident) => {
        fn wait_until(&mut self, t_us: u64) -> Result<(), LineError> {
            self.$field.sleep_until(t_us);
            Ok(())
        }
        fn tolerance_us(&self) -> u64 {
            self.$field.tolerance_us
        }
        fn take_lateness_us(&mut self) -> u64 {
            self.$field.take_lateness_us()
        }
    };
}
pub(crate) use real_time_methods;

/// The clock of a real-time line: µs since the line opened, sleeping until a time,
/// receive stamps, the timing jitter graded with, and how late the harness itself
/// was (its scheduling delay on a busy machine: measured on every timed wait, and as
/// the time it waited for a processor, which also covers a read woken late).
#[derive(Debug, Clone)]
pub struct RealTime {
    epoch: std::time::Instant,
    pub rx: RxClock,
    pub tolerance_us: u64,
    lateness_us: std::cell::Cell<u64>,
    run_delay: std::cell::RefCell<crate::run_delay::RunDelay>,
    /// The harness's own device on the far end (the simulator behind `--port sim`):
    /// how late it was since the last call, which is the harness's too (the model on
    /// a busy machine is late, not wrong).
    pub peer_lateness: Option<std::sync::Arc<std::sync::atomic::AtomicU64>>,
    /// The same device's clock, when it received the latest character and when it
    /// wrote its latest reply.
    pub peer_heard: Option<PeerHeard>,
    /// When the latest write to a pseudo-terminal ended, at the latest (its last
    /// character as a UART would have clocked it out), µs; 0 before any.
    sent_through_us: std::cell::Cell<u64>,
    /// When the first character after that write was read, µs.
    first_read_us: std::cell::Cell<Option<u64>>,
}

/// When the harness's own device on the far end received the latest character and
/// wrote its latest reply, on its clock (µs since `epoch`; a character as it stamps
/// it: a burst read at once is stamped a character time apart). A pseudo-terminal
/// hands a write over through the kernel, and an idle processor wakes the reader late:
/// on this project's 2-core machine, idle, the simulator behind `--port sim` took a
/// request up to 8 ms after it was written and answered it as the model does from
/// when it took it, or the harness read a reply written on time 8 ms late, and the
/// reply was charged as 8 ms late (000:T10) in 4 of 30 runs (2026-11-29). How much
/// later than one end wrote, the other read, is the harness's own lateness each way.
#[derive(Debug, Clone)]
pub struct PeerHeard {
    pub epoch: std::time::Instant,
    pub last_us: std::sync::Arc<std::sync::atomic::AtomicU64>,
    /// When the first run of characters of its latest reply was written (taken just
    /// before the write: it went out no earlier), µs; 0 before any.
    pub wrote_us: std::sync::Arc<std::sync::atomic::AtomicU64>,
}

impl PeerHeard {
    /// A time kept on its clock (`kept`, µs) as an instant; `None` while it is 0.
    fn at(&self, kept: &std::sync::atomic::AtomicU64) -> Option<std::time::Instant> {
        let us = kept.load(std::sync::atomic::Ordering::SeqCst);
        (us > 0).then(|| self.epoch + std::time::Duration::from_micros(us))
    }

    /// How long after the device wrote its latest reply the harness read its first
    /// character (`read_at`), µs: 0 where it was not after, or nothing was written.
    pub fn read_late(&self, read_at: std::time::Instant) -> u64 {
        self.at(&self.wrote_us).map_or(0, |wrote| read_at.saturating_duration_since(wrote).as_micros() as u64)
    }

    /// How long after `sent_at` (the end of the harness's latest write, clocked as a
    /// UART would) the device received its latest character, µs: 0 where it was not
    /// after, or it has received nothing since.
    pub fn late_after(&self, sent_at: std::time::Instant) -> u64 {
        self.at(&self.last_us).map_or(0, |heard| heard.saturating_duration_since(sent_at).as_micros() as u64)
    }
}

impl RealTime {
    pub fn new(tolerance_us: u64) -> RealTime {
        RealTime {
            epoch: std::time::Instant::now(),
            rx: RxClock::default(),
            tolerance_us,
            lateness_us: Default::default(),
            run_delay: std::cell::RefCell::new(crate::run_delay::RunDelay::of_this_thread()),
            peer_lateness: None,
            peer_heard: None,
            sent_through_us: Default::default(),
            first_read_us: Default::default(),
        }
    }

    pub fn now_us(&self) -> u64 {
        self.epoch.elapsed().as_micros() as u64
    }

    /// The instant the clock counts from.
    pub fn epoch(&self) -> std::time::Instant {
        self.epoch
    }

    pub fn sleep_until(&self, t_us: u64) {
        let target = self.epoch + std::time::Duration::from_micros(t_us);
        if let Some(d) = target.checked_duration_since(std::time::Instant::now()) {
            std::thread::sleep(d);
            self.woke(t_us);
        }
    }

    /// A timed wait meant to end at `t_us` has ended: record how late.
    pub fn woke(&self, t_us: u64) {
        let late = self.now_us().saturating_sub(t_us);
        self.lateness_us.set(self.lateness_us.get().max(late));
    }

    /// The longest scheduling delay seen since the last call: the latest timed wait,
    /// or all the time the harness waited for a processor since, if longer; and where
    /// the far end is the harness's own simulator, how late it read or wrote, if later.
    pub fn take_lateness_us(&self) -> u64 {
        let waited = self.run_delay.borrow_mut().take_us().unwrap_or(0);
        let peer = self.peer_lateness.as_ref().map_or(0, |l| l.swap(0, std::sync::atomic::Ordering::SeqCst));
        let at = |us: u64| self.epoch + std::time::Duration::from_micros(us);
        let sent = self.sent_through_us.get();
        let (heard, read) = match &self.peer_heard {
            Some(p) if sent > 0 => (p.late_after(at(sent)), self.first_read_us.get().map_or(0, |r| p.read_late(at(r)))),
            _ => (0, 0),
        };
        self.lateness_us.replace(0).max(waited).max(peer).max(heard).max(read)
    }

    /// A write to a pseudo-terminal ended by `latest_us` (see [`PeerHeard`]).
    pub fn sent_through(&self, latest_us: u64) {
        self.sent_through_us.set(latest_us);
        self.first_read_us.set(None);
    }

    /// A character was read at `at_us`: the first after the latest write is the
    /// reply's (see [`PeerHeard`]).
    pub fn read_at(&self, at_us: u64) {
        if self.first_read_us.get().is_none() {
            self.first_read_us.set(Some(at_us));
        }
    }
}

/// Wait for one byte until `until_us` on the line's clock, in slices of at most
/// 20 ms: `read_within` waits up to the given time (zero: only takes a byte already
/// there) and answers `None` on a timeout (whose lateness is recorded, see
/// [`RealTime::take_lateness_us`]). Past `until_us` it still takes a byte that is
/// already there: a harness that ran late must not call silence what came in time.
pub fn read_until(
    time: &RealTime,
    until_us: u64,
    mut read_within: impl FnMut(std::time::Duration) -> Result<Option<u8>, LineError>,
) -> Result<Option<(u8, u64)>, LineError> {
    loop {
        let t = time.now_us();
        if t > until_us {
            return Ok(read_within(std::time::Duration::ZERO)?.map(|b| (b, time.now_us())));
        }
        let slice = (until_us - t).clamp(100, 20_000);
        match read_within(std::time::Duration::from_micros(slice))? {
            Some(b) => return Ok(Some((b, time.now_us()))),
            None => time.woke(t + slice),
        }
    }
}

/// Write a request in one write and say when the peer received its last character.
///
/// A line without a UART clock delivers one write at once. A peer that stamps what
/// it reads (a program) sees the request end when the write arrived; a peer that
/// plays the UART stamps the characters one character time `ct` apart, so the end is
/// up to (n-1)·ct later. The window holds both. (Writing the characters one at a
/// time instead would narrow it, but on a busy machine the kernel may deliver two of
/// them a timeout apart, and the peer would see two frames: the harness's jitter
/// turned into the device's errors.)
///
/// The write reached the line somewhere between the clock read before it and the one
/// after: the window holds that too, and says how long it was (`Sent::write_us`).
/// Held in the write (a peer at a real-time priority taking the processor as the
/// request arrives, a busy machine), the harness would otherwise pass a late reply on
/// a request end it made up (2026-11-29: a reply 12 ms past its 5 ms limit PASSED
/// once under three busy loops).
pub fn write_whole(
    time: &RealTime,
    ct: u64,
    bytes: &[u8],
    write: impl FnOnce(&[u8]) -> Result<(), LineError>,
) -> Result<Sent, LineError> {
    // Taken before the write: the harness may be descheduled between the write and
    // reading the clock.
    let began = time.now_us();
    write(bytes)?;
    let done = time.now_us();
    let latest_us = done + bytes.len().saturating_sub(1) as u64 * ct;
    time.sent_through(latest_us);
    Ok(Sent { end: Window { earliest_us: began, latest_us }, write_us: done.saturating_sub(began) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_whole_write_ends_between_its_arrival_and_a_clocked_end() {
        let time = RealTime::new(0);
        let mut at = 0;
        let end = write_whole(&time, 2_000, &[1, 2, 3, 4], |_| {
            at = time.now_us();
            Ok(())
        })
        .unwrap()
        .end;
        // A program stamps the write's arrival; a UART player three characters later.
        assert!(end.earliest_us <= at && end.latest_us >= at + 3 * 2_000, "{end:?} {at}");
    }

    #[test]
    fn a_write_the_harness_was_held_in_says_how_long() {
        // Held 5 ms in the write (a peer taking the processor, a busy machine): the
        // request reached the line somewhere in those 5 ms, and the window says so.
        let time = RealTime::new(0);
        let sent = write_whole(&time, 1_000, &[0x40, 0x46, 0x06], |_| {
            std::thread::sleep(std::time::Duration::from_millis(5));
            Ok(())
        })
        .unwrap();
        assert!(sent.write_us >= 5_000, "{sent:?}");
        assert!(sent.end.latest_us - sent.end.earliest_us >= sent.write_us + 2 * 1_000, "{sent:?}");
        // Not held: a write takes microseconds.
        let sent = write_whole(&time, 1_000, &[0x40, 0x46, 0x06], |_| Ok(())).unwrap();
        assert!(sent.write_us < 5_000, "{sent:?}");
    }

    #[test]
    fn a_harness_that_runs_late_still_takes_what_came_in_time() {
        // The deadline has passed when the harness looks (it was descheduled): the
        // byte already there is taken, with one look that does not wait.
        let time = RealTime::new(0);
        let mut waits = Vec::new();
        let got = read_until(&time, 0, |wait| {
            waits.push(wait);
            Ok(Some(0x40))
        })
        .unwrap();
        assert_eq!(got.map(|(b, _)| b), Some(0x40));
        assert_eq!(waits, vec![std::time::Duration::ZERO]);
        // Nothing there: silence, after that one look.
        let mut looks = 0;
        assert_eq!(
            read_until(&time, 0, |_| Ok({
                looks += 1;
                None
            }))
            .unwrap(),
            None
        );
        assert_eq!(looks, 1);
    }

    /// A clock whose far end is the harness's own simulator, which says when it
    /// received and wrote.
    fn clock_with_simulator() -> (RealTime, PeerHeard) {
        let mut clock = RealTime::new(0);
        let heard = PeerHeard { epoch: clock.epoch(), last_us: Default::default(), wrote_us: Default::default() };
        clock.peer_heard = Some(heard.clone());
        (clock, heard)
    }

    /// The simulator took the request 8 ms after the harness wrote it (an idle
    /// processor woke it late): that is the harness's lateness; taken at once, it is
    /// not.
    #[test]
    fn a_request_the_simulator_took_late_is_the_harness_lateness() {
        let (clock, heard) = clock_with_simulator();
        let end = write_whole(&clock, 1_000, &[0x40, 0x50, 0x10], |_| Ok(())).unwrap().end;
        assert!(clock.take_lateness_us() < 8_000, "nothing received yet: not late");
        heard.last_us.store(end.latest_us + 8_000, std::sync::atomic::Ordering::SeqCst);
        assert!(clock.take_lateness_us() >= 8_000, "taken 8 ms after it was written");
        heard.last_us.store(end.latest_us + 100, std::sync::atomic::Ordering::SeqCst);
        assert!(clock.take_lateness_us() < 8_000, "taken at once");
    }

    /// The simulator wrote its reply on time and the harness read it 8 ms later (an
    /// idle processor woke the harness late): the harness's lateness; read at once, not.
    #[test]
    fn a_reply_the_harness_read_late_is_the_harness_lateness() {
        let (clock, heard) = clock_with_simulator();
        let end = write_whole(&clock, 1_000, &[0x40, 0x50, 0x10], |_| Ok(())).unwrap().end;
        heard.wrote_us.store(end.latest_us + 6_000, std::sync::atomic::Ordering::SeqCst);
        clock.read_at(end.latest_us + 14_000);
        assert!(clock.take_lateness_us() >= 8_000, "read 8 ms after it was written");
        write_whole(&clock, 1_000, &[0x40, 0x50, 0x10], |_| Ok(())).unwrap();
        let wrote = heard.wrote_us.load(std::sync::atomic::Ordering::SeqCst);
        clock.read_at(wrote + 100);
        clock.read_at(wrote + 9_000);
        assert!(clock.take_lateness_us() < 8_000, "its first character read at once");
    }

    #[test]
    fn the_simulators_lateness_is_the_harness_and_taken_once() {
        let mut clock = RealTime::new(0);
        let peer = std::sync::Arc::new(std::sync::atomic::AtomicU64::new(0));
        clock.peer_lateness = Some(peer.clone());
        peer.store(7_000, std::sync::atomic::Ordering::SeqCst);
        assert!(clock.take_lateness_us() >= 7_000, "the simulator's 7 ms late reply is the harness's");
        assert_eq!(peer.load(std::sync::atomic::Ordering::SeqCst), 0, "taken: the next exchange starts from nothing");
        assert!(clock.take_lateness_us() < 7_000);
    }
}
