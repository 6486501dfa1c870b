//! Reading a capture on its own thread while the listener grades: text parsing is a
//! third of `decode`'s work, so on two cores the two stages run side by side. The
//! reader runs ahead by a bounded number of batches (memory stays constant in the
//! capture's length), stops at its first error, and stops when the listener stops
//! asking (a dropped receiver), so neither side can hang on the other.

use super::{Capture, Event, ParseError, Run};
use std::sync::mpsc::{sync_channel, Receiver};
use std::thread::Scope;

/// Runs per batch: large enough that the channel costs nothing per run.
const BATCH: usize = 4096;
/// Batches the reader may run ahead.
const AHEAD: usize = 4;

struct Batch {
    runs: Vec<Result<Run, ParseError>>,
    /// The reader's channels and assumptions once this batch was read.
    channels: Vec<String>,
    assumptions: Vec<String>,
}

/// A capture read ahead on a thread of `scope`: the same events, channels and
/// assumptions as `capture`, in the same order.
pub fn prefetch<'scope, 'env: 'scope>(
    scope: &'scope Scope<'scope, 'env>,
    mut capture: Box<dyn Capture + 'env>,
) -> Prefetched {
    let tolerance_us = capture.tolerance_us();
    let channels = capture.channels();
    let assumptions = capture.assumptions();
    let (tx, rx) = sync_channel(AHEAD);
    scope.spawn(move || loop {
        // The capture's runs, not its events: a capture of whole frames crosses over
        // a frame at a time.
        let mut runs = Vec::with_capacity(BATCH);
        let mut stop = false;
        while runs.len() < BATCH {
            match capture.next_run() {
                Some(r) => {
                    stop = r.is_err();
                    runs.push(r);
                    if stop {
                        break;
                    }
                }
                None => {
                    stop = true;
                    break;
                }
            }
        }
        let batch = Batch { runs, channels: capture.channels(), assumptions: capture.assumptions() };
        if tx.send(batch).is_err() || stop {
            return;
        }
    });
    Prefetched { rx, current: Vec::new().into_iter(), run: None, channels, assumptions, tolerance_us }
}

/// The listener's side of [`prefetch`].
pub struct Prefetched {
    rx: Receiver<Batch>,
    current: std::vec::IntoIter<Result<Run, ParseError>>,
    /// The run being handed out event by event, and its next event.
    run: Option<(Run, usize)>,
    channels: Vec<String>,
    assumptions: Vec<String>,
    tolerance_us: Option<u64>,
}

impl Prefetched {
    /// The next run of the batches, whole.
    fn next_whole(&mut self) -> Option<Result<Run, ParseError>> {
        loop {
            if let Some(r) = self.current.next() {
                return Some(r);
            }
            let batch = self.rx.recv().ok()?;
            self.current = batch.runs.into_iter();
            self.channels = batch.channels;
            self.assumptions = batch.assumptions;
        }
    }
}

impl Iterator for Prefetched {
    type Item = Result<Event, ParseError>;
    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some((run, n)) = &mut self.run {
                if let Some(e) = run.events().nth(*n) {
                    *n += 1;
                    return Some(Ok(e));
                }
                self.run = None;
            }
            match self.next_whole()? {
                Ok(run) => self.run = Some((run, 0)),
                Err(e) => return Some(Err(e)),
            }
        }
    }
}

impl Capture for Prefetched {
    /// The channels the reader has seen, which may be ahead of the events handed
    /// out: channels are only ever added, so an index stays valid.
    fn channels(&self) -> Vec<String> {
        self.channels.clone()
    }
    fn assumptions(&self) -> Vec<String> {
        self.assumptions.clone()
    }
    fn tolerance_us(&self) -> Option<u64> {
        self.tolerance_us
    }
    fn next_run(&mut self) -> Option<Result<Run, ParseError>> {
        // What is left of a run begun event by event comes first.
        if let Some((run, n)) = self.run.take() {
            if let Some(rest) = run.from_nth(n) {
                return Some(Ok(rest));
            }
        }
        self.next_whole()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::capture::{open, Format, ReadOptions};

    const OPTIONS: ReadOptions = ReadOptions { baud: 9600, samplerate_hz: Some(1_000_000) };

    fn log(lines: usize) -> String {
        (0..lines).map(|i| format!("{:.3} ms  M> 40 42 02\n", 10.0 + 40.0 * i as f64)).collect()
    }

    /// Read ahead or not, a capture gives the same events, channels and assumptions,
    /// across several batches.
    #[test]
    fn prefetching_changes_nothing_but_the_thread() {
        let text = log(BATCH + 7);
        let direct: Vec<_> = open(Box::new(text.as_bytes()), Some(Format::Wirelog), OPTIONS).unwrap().1.collect();
        let (_, capture) = open(Box::new(text.as_bytes()), Some(Format::Wirelog), OPTIONS).unwrap();
        let (ahead, channels, assumptions) = std::thread::scope(|s| {
            let mut p = prefetch(s, capture);
            let events: Vec<_> = p.by_ref().collect();
            (events, p.channels(), p.assumptions())
        });
        assert!(direct.len() > BATCH, "{} events: not several batches", direct.len());
        assert_eq!(ahead, direct);
        let (_, mut c) = open(Box::new(text.as_bytes()), Some(Format::Wirelog), OPTIONS).unwrap();
        c.by_ref().for_each(drop);
        assert_eq!((channels, assumptions), (c.channels(), c.assumptions()));
    }

    /// An error ends the stream where it stands, and a listener that stops early
    /// does not leave the reader blocked (the scope would not end).
    #[test]
    fn an_error_ends_it_and_stopping_early_does_not_hang() {
        let text = format!("{}garbage\n{}", log(2 * BATCH), log(10));
        let (_, capture) = open(Box::new(text.as_bytes()), Some(Format::Wirelog), OPTIONS).unwrap();
        let events: Vec<_> = std::thread::scope(|s| prefetch(s, capture).collect());
        assert_eq!(events.iter().filter(|e| e.is_err()).count(), 1);
        assert!(events.last().is_some_and(|e| e.is_err()), "the error is the last item");
        let (_, capture) = open(Box::new(text.as_bytes()), Some(Format::Wirelog), OPTIONS).unwrap();
        let first = std::thread::scope(|s| prefetch(s, capture).next());
        assert!(first.is_some_and(|e| e.is_ok()));
    }
}
