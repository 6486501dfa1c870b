//! The case catalogue for slave certification, one file per area of the spec. Each
//! case names its clauses; the oracle grades every exchange; cases add checks across
//! exchanges (data read back, state restored). Cases that write restore what they
//! changed. Requests are typed (`hiperface_model::Request`); only frames that no
//! request expresses (unknown commands, wrong lengths, bad checksums) are bytes.

mod addressing;
mod analog;
mod codes;
mod counter;
mod fields;
mod identity;
mod position;
mod powerup;
mod protocol;
mod settings;
mod timing;

use super::{Case, CaseError, Ctx, Guard};
use hiperface_model::{CommandId, Edition, Profile, Request, Response, ResponseFrame, UartSettings};

type Res = Result<(), CaseError>;

/// Every case, in run order: reads first, then what writes and restores, then what
/// resets the device.
pub fn catalogue() -> Vec<Case> {
    vec![
        identity::TYPE_LABEL,
        identity::VERSION,
        identity::STATUS,
        position::READ,
        addressing::BROADCAST,
        addressing::OTHER,
        protocol::CHECKSUM,
        protocol::PARITY,
        protocol::UNKNOWN_COMMAND,
        protocol::LENGTH,
        protocol::ARGUMENT,
        analog::CHANNELS,
        counter::READ,
        counter::INCREMENT,
        fields::STATUS,
        fields::LIFECYCLE,
        fields::ACCESS_CODE,
        fields::CODE_NUMBERS,
        fields::RESIZE,
        fields::MEMORY_EXHAUSTION,
        fields::EXTENDED_TYPE_LABEL,
        fields::EXTENDED_TYPE_LABEL_READ_ONLY,
        codes::CHANGE_RESTORE,
        addressing::CHANGE_RESTORE,
        position::SET,
        position::SYNC,
        position::ADJUSTMENT_ERRORS,
        position::ADJUSTMENT,
        position::LEGACY_SET_POSITION_SYNC,
        position::SYNC_OFFSET,
        settings::INVALID,
        settings::TEMPORARY,
        settings::STORED,
        powerup::RESET,
        powerup::DEFAULT_WINDOW,
        powerup::WINDOW,
        powerup::RETAINS,
        timing::READ_POSITION,
    ]
}

/// A case: id, title, clauses (registry identifiers), what it needs, when it applies,
/// and its body.
macro_rules! case {
    ($id:literal, $title:literal, [$($clause:ident),*], $needs:ident, $applies:expr, $run:expr) => {
        $crate::slave::Case {
            id: $id,
            title: $title,
            clauses: const { &[$(hiperface_model::clause::$clause.clause()),*] },
            needs: $crate::slave::Needs::$needs,
            applies: $applies,
            run: $run,
        }
    };
}
use case;

fn always(_: &Profile) -> Option<&'static str> {
    None
}

/// Not applicable, for `why`, where the profile lacks the command `id`.
fn lacks(p: &Profile, id: CommandId, why: &'static str) -> Option<&'static str> {
    (!p.commands.contains(id)).then_some(why)
}

fn current_edition(p: &Profile) -> Option<&'static str> {
    (p.edition != Edition::Current)
        .then_some("the legacy edition has no silent settings-change window; a profile of the current edition runs it")
}

/// A supported data rate other than the default, for 67h.
fn other_baud(p: &Profile) -> Option<UartSettings> {
    hiperface_model::settings::Baud::ALL
        .into_iter()
        .rev()
        .find(|b| *b != UartSettings::DEFAULT.baud && p.supports_baud(*b))
        .map(|baud| UartSettings { baud, ..UartSettings::DEFAULT })
}

fn code0(c: &Ctx<'_>) -> u8 {
    c.model.nonvolatile().codes[0]
}

/// Read Position; the position, or `None` when the reply is no position (an error, or a
/// reply that does not decode: a wrong checksum says nothing of the value).
fn read_position(c: &mut Ctx<'_>) -> Result<Option<u32>, CaseError> {
    let reply = c.request(Request::ReadPosition)?.reply;
    Ok(match decoded(reply.as_deref(), CommandId::ReadPosition) {
        Some(Response::Position(p)) => Some(p),
        _ => None,
    })
}

/// A reply to `command` as it decodes, if it does.
fn decoded(reply: Option<&[u8]>, command: CommandId) -> Option<Response> {
    ResponseFrame::decode(reply?, command).ok().map(|f| f.response)
}

/// After errors were answered: Read Encoder Status. Protocol and data errors are
/// answered, never stacked (000:T37); the oracle FAILs such a code read back (a
/// stack that takes every error reply is otherwise seen only as a warning bit, which
/// a real condition the harness cannot see may also set).
fn errors_not_stacked(c: &mut Ctx<'_>) -> Res {
    c.request(Request::ReadEncoderStatus).map(drop)
}

fn release(c: &mut Ctx<'_>, g: Option<Guard>) {
    if let Some(g) = g {
        c.release(g);
    }
}

fn wait_until(c: &mut Ctx<'_>, t_us: u64) -> Res {
    let now = c.now_us();
    if t_us > now {
        c.wait_ms((t_us - now).div_ceil(1000))?;
    }
    Ok(())
}
