//! The reference master's transcript in virtual time: every request it sends (when, and
//! its bytes), every wait it asks for and every line it tells the operator, against the
//! model on a virtual line with each scenario's faults injected, as a snapshot
//! (`tests/snapshots/reference_master__*.snap`). The reference master's decisions live
//! in the model (`hiperface_model::master::reference`) and its driver here: a change of
//! what it does, or when, shows in the snapshot and is reviewed with it.

use hiperface_conformance::master;
use hiperface_model::datalink::RxChar;
use hiperface_model::slave::act::{Acted, ActedReply};
use hiperface_model::{profiles, Edition, Profile, Slave, Transmission, UartSettings};
use hiperface_suite::exchange::BusMaster;
use hiperface_suite::line::virtual_line::{SlaveDevice, VirtualLine};
use hiperface_suite::line::{Line, LineError, LineKind, Sent, Window};
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::fmt::Write;
use std::rc::Rc;

/// The model with a scenario's plan applied as the harness's encoder applies it
/// (`suite::master::encoder`): the `nth` request of a command gets the act.
struct Scripted {
    slave: Slave,
    plan: &'static [hiperface_suite::master::scenario::Injection],
    /// The plan's injections that have taken place (each once).
    fired: std::collections::BTreeSet<usize>,
    seen: BTreeMap<u8, u32>,
    /// A gap inside the reply on its way: before which character, how long.
    gap: Option<(usize, u64)>,
}

impl Scripted {
    fn act(&mut self, step: hiperface_model::Step) -> Option<Transmission> {
        let Ok(request) = hiperface_model::RequestFrame::decode(step.received.bytes.as_bytes()) else {
            return step.transmission;
        };
        let command = request.request.command();
        let n = {
            let c = self.seen.entry(command.byte()).or_default();
            *c += 1;
            *c
        };
        let mut tx = step.transmission;
        self.gap = None;
        let due: Vec<usize> = (0..self.plan.len())
            .filter(|i| self.plan[*i].due(command, n, step.received.last_us, self.fired.contains(i)))
            .collect();
        self.fired.extend(due.iter().copied());
        for inj in due.iter().map(|i| &self.plan[*i]) {
            // On from the next request (this one was answered as the model had it).
            if let Some(f) = inj.act.position_fault() {
                self.slave.inject_position_fault(f, true);
                continue;
            }
            let Some(t) = tx.as_mut() else { continue };
            let address = step.received.bytes.as_bytes().first().copied().unwrap_or(0x40);
            let mut reply = ActedReply { frame: t.frame, start_us: t.earliest_start_us, gap: None };
            match inj.act.apply(address, &mut reply) {
                Acted::Sent => {
                    (t.frame, t.earliest_start_us) = (reply.frame, reply.start_us);
                    self.gap = reply.gap.or(self.gap);
                }
                Acted::Silent => tx = None,
                Acted::Restart => {
                    self.slave.power_cycle(step.received.complete_us);
                    tx = None;
                }
            }
        }
        tx
    }
}

impl SlaveDevice for Scripted {
    fn receive(&mut self, ch: RxChar) -> Option<Transmission> {
        let step = self.slave.receive(ch)?;
        self.act(step)
    }
    fn poll(&mut self, now_us: u64) -> Option<Transmission> {
        let step = self.slave.poll(now_us)?;
        self.act(step)
    }
    fn next_deadline(&self, now_us: u64) -> Option<u64> {
        self.slave.next_deadline(now_us)
    }
    fn listening_settings(&self, now_us: u64) -> Option<UartSettings> {
        self.slave.listening_settings(now_us)
    }
    fn extra_gap_before_us(&self, index: usize) -> u64 {
        self.gap.filter(|(before, _)| *before == index).map_or(0, |(_, us)| us)
    }
    fn edition(&self) -> Edition {
        self.slave.profile().edition
    }
}

/// A line that writes what the master does on it into the transcript.
struct Recording<L: Line> {
    line: L,
    out: Rc<RefCell<String>>,
}

impl<L: Line> Line for Recording<L> {
    fn now_us(&mut self) -> u64 {
        self.line.now_us()
    }
    fn send(&mut self, bytes: &[u8]) -> Result<Sent, LineError> {
        let now = self.line.now_us();
        let hex: Vec<String> = bytes.iter().map(|b| format!("{b:02X}")).collect();
        let _ = writeln!(self.out.borrow_mut(), "{now:>9} > {}", hex.join(" "));
        self.line.send(bytes)
    }
    fn recv(&mut self, until_us: u64) -> Result<Option<RxChar>, LineError> {
        self.line.recv(until_us)
    }
    fn start_of(&self, ch: &RxChar) -> Window {
        self.line.start_of(ch)
    }
    fn wait_until(&mut self, t_us: u64) -> Result<(), LineError> {
        let _ = writeln!(self.out.borrow_mut(), "{:>9} wait until {t_us}", self.line.now_us());
        self.line.wait_until(t_us)
    }
    fn configure(&mut self, settings: UartSettings) -> Result<(), LineError> {
        self.line.configure(settings)
    }
    fn settings(&self) -> UartSettings {
        self.line.settings()
    }
    fn kind(&self) -> LineKind {
        self.line.kind()
    }
    fn describe(&self) -> String {
        self.line.describe()
    }
}

/// The reference master against `profile`'s encoder in every scenario's world, with
/// its plan, for `duration_ms` of line time.
fn transcript(profile: Profile, polling_period_ms: u64, duration_ms: u64) -> String {
    let mut all = String::new();
    for scenario in hiperface_suite::master::scenarios::catalogue() {
        let encoder = scenario.encoder.map_or(profile, |make| make(profile));
        let mut slave = Slave::new(encoder);
        (scenario.world)(&encoder).apply_at_power_on(&mut slave);
        let device =
            Scripted { slave, plan: scenario.plan, fired: Default::default(), seen: BTreeMap::new(), gap: None };
        let out = Rc::new(RefCell::new(String::new()));
        let line = Recording { line: VirtualLine::new(device), out: out.clone() };
        let mut bus = BusMaster::new(line, encoder.edition);
        let options = hiperface_model::master::reference::Options { polling_period_ms, duration_ms: Some(duration_ms) };
        let console = out.clone();
        let result = master::reference::run(&mut bus, encoder, options, &mut |text: &str| {
            let _ = writeln!(console.borrow_mut(), "          | {text}");
        });
        let _ = writeln!(all, "== {} ({:?})", scenario.id, result.map_err(|e| e.to_string()));
        all.push_str(&out.borrow());
    }
    all
}

#[test]
fn the_reference_masters_transcript_current_edition() {
    insta::assert_snapshot!(transcript(profiles::srs50(), 50, 2_500));
}

#[test]
fn the_reference_masters_transcript_legacy_edition() {
    insta::assert_snapshot!(transcript(profiles::legacy_srs(), 50, 2_500));
}

/// Faults that persist: the master retries, resets three times, then stops reading the
/// position and reads the status now and then.
#[test]
fn the_reference_masters_transcript_when_faults_persist() {
    insta::assert_snapshot!(transcript(profiles::sek37(), 20, 4_000));
}

/// The joint exploration of the reference master (proofs/src/master_fixpoint/) runs
/// on its own model of the line: with the encoder answering every request, its
/// master decides at the same instants and asks the same things as the reference
/// master on the harness's `BusMaster` over the virtual line, both editions.
#[test]
fn the_exploration_times_the_reference_master_as_the_harness_does() {
    use hiperface_model::master::reference::{Action, Done, ReferenceMaster};
    use hiperface_proofs::master_fixpoint as mf;
    for profile in [profiles::sek37(), profiles::legacy_srs()] {
        let world = &mf::worlds(profile)[0];
        assert_eq!(world.name, "calm");
        let steps = 60;
        let explored: Vec<(u64, Action)> = mf::play(world, mf::reference_step, std::iter::repeat_n(None, steps))
            .into_iter()
            .map(|s| (s.at_us, s.action))
            .collect();
        // The driver's loop (conformance/src/master/reference.rs), each decision noted.
        let mut bus = BusMaster::new(VirtualLine::new(Slave::new(profile)), profile.edition);
        let options =
            hiperface_model::master::reference::Options { polling_period_ms: mf::POLLING_PERIOD_MS, duration_ms: None };
        let mut machine = ReferenceMaster::new(profile, options);
        let mut action = machine.power_on();
        let mut harness = Vec::new();
        for _ in 0..steps {
            harness.push((bus.now_us(), action));
            action = match action {
                Action::Stop => break,
                Action::WaitUntil(t) => {
                    bus.line.wait_until(t).unwrap();
                    machine.next(Done::Waited { now_us: bus.now_us() }, &mut |_| {})
                }
                Action::Exchange { request, listen_ms } => {
                    let x = bus.exchange(request.encode().as_bytes(), listen_ms).unwrap();
                    let reply = x.reply_bytes().unwrap_or_default();
                    let done = Done::Exchanged {
                        now_us: bus.now_us(),
                        request_end_us: x.request_end.latest_us,
                        timeout_us: x.timeout_us,
                        reply: &reply,
                    };
                    machine.next(done, &mut |_| {})
                }
            };
        }
        assert_eq!(explored, harness, "{}", profile.name.as_str());
    }
}

/// The exploration's encoder does every act the scenario catalogue injects, in every
/// world and encoder the catalogue has.
#[test]
fn the_exploration_covers_the_catalogues_acts_and_worlds() {
    use hiperface_proofs::master_fixpoint as mf;
    let profile = profiles::sek37();
    let acts = mf::acts();
    let worlds = mf::worlds(profile);
    for scenario in hiperface_suite::master::scenarios::catalogue() {
        for inj in scenario.plan {
            let act = Some(inj.act);
            assert!(acts.contains(&act), "{}: {act:?} not explored", scenario.id);
        }
        let world = (scenario.world)(&profile);
        let encoder = scenario.encoder.map_or(profile, |make| make(profile));
        let hot = world.inputs.is_some_and(|i| i.temperature_c > encoder.temperature_max_c);
        let same = |w: &&mf::World| {
            w.init_faults == world.init_faults
                && w.hot == hot
                && w.encoder.type_code == encoder.type_code
                && w.encoder.settings == encoder.settings
                && w.encoder.init_ms == encoder.init_ms
        };
        assert!(worlds.iter().any(|w| same(&w)), "{}: its world is not explored", scenario.id);
    }
}
