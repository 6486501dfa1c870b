//! The Kani harnesses of the model's properties (`scripts/kani.sh` runs each), each
//! with its `cargo test` twin in `properties::PROPERTIES` (the tests in lib.rs hold the
//! two lists equal, name by name and domain by domain).
//!
//! Long because: one harness per property, 52 of them, each with the `Domain:` line its
//! twin repeats and the argument for its unwind bound; split, the two lists' check
//! would read several files for one registry.
//!
//! Each harness's first doc line is `Domain: ...`, in the words of its twin's
//! `Property::domain` (a test compares the two); then why its unwind bound suffices.
//! Unwinding assertions are on (Kani's default): a bound that is too small fails.

use super::*;
use crate::properties as p;
use hiperface_model::slave::fields::FieldMemory;

/// Domain: every 3-byte body, every bit of the 4-byte frame.
/// No loop depends on the inputs (the XOR runs over 3 or 4 bytes).
#[kani::proof]
fn checksum() {
    let body: [u8; 3] = kani::any();
    let bit: usize = kani::any();
    kani::assume(bit < 32);
    assert!(checksum_detects_single_bit_flips(body, bit));
}

/// Domain: all 256 settings bytes.
#[kani::proof]
fn settings_codec() {
    assert!(settings_codec_round_trips(kani::any()));
}

/// Domain: all 256 address bytes.
#[kani::proof]
fn address_codec() {
    assert!(address_codec_round_trips(kani::any()));
}

/// Domain: the 16 rows of 000 Table 72.
/// Unwind 17: the search runs over the 16 rows (+1 for the exit check).
#[kani::proof]
#[kani::unwind(17)]
fn quadrature_table() {
    let row: u8 = kani::any();
    kani::assume(row < 16);
    assert!(quadrature_equals_table_72(row));
}

/// Domain: the 16 rows of 000:3.2.5's table.
/// Unwind 17: the search runs over the 16 rows (+1 for the exit check).
#[kani::proof]
#[kani::unwind(17)]
fn sync_table() {
    let (f, a): (u8, u8) = (kani::any(), kani::any());
    kani::assume(f < 4 && a < 4);
    assert!(sync_equals_table(f, a));
}

/// Domain: sin and cos in -128..=127.
#[kani::proof]
fn octants() {
    let (s, c): (i8, i8) = (kani::any(), kani::any());
    assert!(octant_transformation_is_sound(s as i32, c as i32));
}

/// Domain: all 256 command bytes.
#[kani::proof]
fn command_byte_codec() {
    assert!(p::command_byte_round_trips(kani::any()));
}

/// Domain: every frame of 0 to 6 bytes.
/// Unwind 8: the loops run over the frame's bytes (at most 6, +1 for the exit
/// check).
#[kani::proof]
#[kani::unwind(8)]
fn request_decoder() {
    let frame: [u8; 6] = kani::any();
    let len: usize = kani::any();
    kani::assume(len <= 6);
    assert!(p::request_decoder_is_total(&frame[..len]));
}

/// Domain: a command byte and 0 to 6 reply bytes.
/// Unwind 8: the loops run over the reply's bytes (at most 6, +1 for the exit
/// check). Run with CBMC's `--max-field-sensitivity-array-size 136`
/// (scripts/kani.sh; docs/src/design.md, "Kani"): without it CBMC 6.6 misreads the
/// fields of a `Response`.
#[kani::proof]
#[kani::unwind(8)]
fn response_decoder() {
    let data: [u8; 7] = kani::any();
    let len: usize = kani::any();
    kani::assume(len <= 7);
    crate::targets::response(&data[..len]);
}

/// Domain: every command of fixed length, any data bytes.
/// Unwind 9: the loops run over the frame's bytes (at most 8: address, command, 5
/// data bytes, checksum; +1 for the exit check).
#[kani::proof]
#[kani::unwind(9)]
fn request_round_trip_fixed() {
    let row: u8 = kani::any();
    kani::assume((row as usize) < hiperface_model::COMMAND_TABLE.len() && row != p::STORE_DATA_ROW);
    let data: [u8; 5] = kani::any();
    assert!(p::request_round_trips(row, &data));
}

/// Domain: Store Data with 1 to 128 data bytes, any header and data bytes.
/// Unwind 136: the loops run over the frame's bytes (at most 135, +1 for the exit
/// check).
#[kani::proof]
#[kani::unwind(136)]
fn request_round_trip_store_data() {
    let data: [u8; 132] = kani::any();
    let len: usize = kani::any();
    kani::assume((5..=132).contains(&len));
    assert!(p::request_round_trips(p::STORE_DATA_ROW, &data[..len]));
}

/// Domain: any timeout, 4 characters with any bytes and gaps.
/// Unwind 5: the longest loop is over the 4 characters (+1 for the exit check).
#[kani::proof]
#[kani::unwind(5)]
fn datalink() {
    let timeout: u16 = kani::any();
    let chars: [(u8, u16); 4] = kani::any();
    assert!(p::datalink_frames(timeout, &chars));
}

/// Domain: every sequence of 6 operations over 5 codes and pop.
/// Unwind 7: the loop over the 6 operations (+1); the stack's own loops are over
/// its 4 slots.
#[kani::proof]
#[kani::unwind(7)]
fn stack() {
    let ops: [u8; 6] = kani::any();
    for o in ops {
        kani::assume(o < 6);
    }
    assert!(p::stack_invariants(&ops));
}

/// Domain: every error stack satisfying the invariant (any 4 codes, the first 0 to 4 pushed), then one push of any code, pop (either order) or clear.
/// Unwind 5: the stack's loops run over its 4 slots (+1).
#[kani::proof]
#[kani::unwind(5)]
fn inductive_stack() {
    let (codes, len, op, code) = (kani::any(), kani::any(), kani::any(), kani::any());
    kani::assume(len <= 4);
    kani::cover!(len == 4 && op % 4 == 0, "a push on a full stack");
    assert!(crate::inductive::stack_step_keeps_invariant(codes, len, op, code));
}

/// Domain: every data field table of at most 3 fields satisfying the invariant, on any memory size, then one create, change or delete of a field with any status.
/// Unwind 6: the table's loops run over its fields (at most 4 after a create, +1)
/// and `FieldTable::from_table`'s over the 3 statuses given; the invariant's over
/// the fields. The table alone (`FieldTable`, the statuses and the memory's size):
/// `DataFields` changes it only through these three operations, and its 4 080
/// bytes of contents, which none of them reads, are not in the proof (with them,
/// no verdict in 6 minutes at 3.7 GB).
#[kani::proof]
#[kani::unwind(6)]
fn inductive_data_fields() {
    let step: crate::inductive::FieldsStep = kani::any();
    kani::cover!(step.count == 3 && step.op % 3 == 0, "a create on a table of 3 fields");
    assert!(crate::inductive::fields_step_keeps_invariant(&step));
}

/// Domain: erased memory, any position, any count, any byte probed.
/// No loop: the read is compared in length and at one symbolic byte.
#[kani::proof]
fn field_memory_read() {
    let (start, count, probe) = (kani::any(), kani::any(), kani::any());
    assert!(crate::inductive::field_memory_reads_as_stubbed(start, count, probe));
}

/// Domain: erased memory, 0 to 8 bytes written at any position.
/// Unwind 9: the write's loop over the bytes it writes (at most 8, +1). No
/// assertion here reads what it writes; with the contents read back (the property
/// `field_memory_contents`) no verdict in 300 s.
#[kani::proof]
#[kani::unwind(9)]
fn field_memory_write() {
    let data: [u8; 8] = kani::any();
    let len: usize = kani::any();
    kani::assume(len <= 8);
    assert!(crate::inductive::field_memory_writes_as_stubbed(kani::any(), &data[..len]));
}

/// Domain: erased memory, any range freed.
/// Unwind 129: `free`'s loop over the bytes of its 8 blocks (128, +1).
#[kani::proof]
#[kani::unwind(129)]
fn field_memory_free() {
    assert!(crate::inductive::field_memory_frees_without_panic(kani::any(), kani::any()));
}

/// Domain: any memory state (any contents, any bitmap of known bytes), a read of any count at any position, any byte probed.
/// Unwind 9 (no loop: the read is compared in length and at one symbolic byte). The
/// 4 591 bytes of the state are one symbolic array each (contents, bitmap), not a
/// window: no loop runs over them.
#[kani::proof]
#[kani::unwind(9)]
fn field_memory_any_read() {
    let op = crate::contents::MemoryOp { kind: crate::contents::READ, ..kani::any() };
    assert!(crate::contents::memory_ops_from_any(&kani::any(), &[op], kani::any(), true));
}

/// Domain: any memory state (any contents, any bitmap of known bytes), 0 to 8 bytes written at any position, any byte probed.
/// Unwind 9: the write's loop over the bytes it writes (at most 8, +1). Its answer
/// and no panic (a byte at `at % 8 == 7` known already, written again, is where
/// `+=` for `|=` overflows); what it writes, read back, had no verdict in 420 s
/// (2026-11-28): sampled by the twin.
#[kani::proof]
#[kani::unwind(9)]
fn field_memory_any_write() {
    let op = crate::contents::MemoryOp { kind: crate::contents::WRITE, ..kani::any() };
    kani::assume(op.len <= 8);
    assert!(crate::contents::memory_ops_from_any(&kani::any(), &[op], kani::any(), false));
}

/// Domain: any memory state (any contents, any bitmap of known bytes), 0 to 8 bytes written at the second block (byte 16), any byte probed.
/// Unwind 9: the write's loop (at most 8, +1). At a start it knows, each store and
/// each bitmap byte it reads is one CBMC knows. CaDiCaL: on `+=` for `|=` (issue 60)
/// MiniSat had no verdict in 300 s here and at any start (`field_memory_any_write`,
/// 2026-11-29); CaDiCaL FAILs it on the overflow in 66 s.
#[kani::proof]
#[kani::unwind(9)]
#[kani::solver(cadical)]
fn field_memory_any_write_block() {
    let op = crate::contents::MemoryOp { kind: crate::contents::WRITE, at: crate::contents::FREE_BLOCK, ..kani::any() };
    kani::assume(op.len <= 8);
    assert!(crate::contents::memory_ops_from_any(&kani::any(), &[op], kani::any(), false));
}

/// Domain: any memory state (any contents, any bitmap of known bytes), any range freed, any byte probed.
/// Unwind 129: `free`'s loop over the bytes of its 8 blocks (128, +1). Its answer
/// (none) and no panic; what it does to the bytes is `field_memory_any_free_block`'s
/// (read back after a free at a position the harness does not know: no verdict in
/// 300 s, 2026-11-28).
#[kani::proof]
#[kani::unwind(129)]
fn field_memory_any_free() {
    let op = crate::contents::MemoryOp { kind: 2, ..kani::any() };
    assert!(crate::contents::memory_ops_from_any(&kani::any(), &[op], kani::any(), false));
}

/// Domain: any memory state (any contents, any bitmap of known bytes), a free from the second block (byte 16) to any end, any byte probed.
/// Unwind 129: `free`'s loop (128, +1). Read back: every byte and bit afterwards as
/// the reference has it. One start, where a field after the first begins: at a
/// start the harness does not know each of the 256 stores is one into the whole
/// memory (no verdict in 300 s); the bytes' fate depends on the start only through
/// `at - from`, `at / 8` and `at % 8` (docs/src/verification.md).
#[kani::proof]
#[kani::unwind(129)]
fn field_memory_any_free_block() {
    let op = crate::contents::MemoryOp { kind: 2, at: crate::contents::FREE_BLOCK, ..kani::any() };
    assert!(crate::contents::memory_ops_from_any(&kani::any(), &[op], kani::any(), true));
}

/// Domain: any memory state (any contents, any bitmap of known bytes), two operations in a row (each a read or a write of 0 to 2 bytes, at any position), any byte probed.
/// Unwind 3: the write's loop over at most 2 bytes (+1). No free: with one at a
/// position the harness does not know, no verdict in 300 s (2026-11-28). Answers
/// and no panic, as `field_memory_any_write`.
#[kani::proof]
#[kani::unwind(3)]
fn field_memory_any_two() {
    let ops: [crate::contents::MemoryOp; 2] = kani::any();
    kani::assume(ops[0].len <= 2 && ops[1].len <= 2 && ops[0].kind % 3 != 2 && ops[1].kind % 3 != 2);
    assert!(crate::contents::memory_ops_from_any(&kani::any(), &ops, kani::any(), false));
}

/// One frame of `command` from every state of a SEK37 satisfying the invariant, as
/// [`inductive_command_where`], with the field memory's operations as the harness's
/// stubs give them: the contents are reached by nothing but those operations
/// (`FieldMemory` is a module of its own, model/src/slave/fields/memory.rs), whose
/// answers depend on positions and lengths alone from any memory state
/// (`field_memory_any_*`) but for the bytes `read` answers. So a step that reaches no
/// other operation of the memory, and whose outcome depends on what `read` answers only
/// in Read Data's data bytes, is blind to the contents and to the bitmap of known
/// bytes. `twice`: the step run a second time from the same state, each `read` in each
/// answering any bytes (`read_any`), compared as `contents::step_blind_to_reads` does;
/// without it, for commands whose stubs refuse `read`: one step, deterministic but for
/// the stubs' answers, which no content decides.
fn contents_blind_command<const N: usize>(command: u8, admit: fn(&[u8; N]) -> bool, twice: bool) {
    let (state, frame) = any_state_and_frame::<N>(hiperface_model::profiles::sek37, command, admit);
    let (now, fault) = (kani::any(), kani::any());
    if twice {
        assert!(crate::contents::step_blind_to_reads(&state, &frame, now, fault));
    } else {
        let _ = state.clone().handle(&frame, fault, now);
    }
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields) on two memories in any states (Kani: the memory reached only through its operations, any bytes read), every frame of Read Data (4Ah) asking for 0 to 16 or more than 128 bytes at any time, with and without a UART fault.
/// Unwind 23, as `inductive_read_data` (a reply of up to 22 bytes). Two steps, each
/// `read` answering any bytes; `write`, `free`, `is_known` and `is_free_from` refused.
#[kani::proof]
#[kani::unwind(23)]
#[kani::solver(cadical)]
#[kani::stub(hiperface_model::slave::fields::memory::FieldMemory::read, read_any)]
#[kani::stub(hiperface_model::slave::fields::memory::FieldMemory::write, write_refused)]
#[kani::stub(hiperface_model::slave::fields::memory::FieldMemory::free, free_refused)]
#[kani::stub(hiperface_model::slave::fields::memory::FieldMemory::is_known, is_known_refused)]
#[kani::stub(hiperface_model::slave::fields::memory::FieldMemory::is_free_from, is_free_from_refused)]
fn contents_blind_read_data() {
    contents_blind_command::<7>(0x4A, |f| crate::inductive::read_data_counted_short(f), true);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields) on two memories in any states (Kani: the memory reached only through its operations, any bytes read), every frame of Store Data (4Bh) with 1 data byte at any time, with and without a UART fault.
/// Unwind 10, as `inductive_store_data_one_byte`. One step: `write` answering as
/// from any state, `read`, `free`, `is_known` and `is_free_from` refused
/// (`scripts/kani.sh --false-assertion`: `write` refused too, which a stored byte
/// reaches: [`write_claimed_unreached`]).
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
#[kani::stub(hiperface_model::slave::fields::memory::FieldMemory::read, read_refused)]
#[cfg_attr(
    not(false_assertion),
    kani::stub(hiperface_model::slave::fields::memory::FieldMemory::write, write_answers_only)
)]
#[cfg_attr(
    false_assertion,
    kani::stub(hiperface_model::slave::fields::memory::FieldMemory::write, write_claimed_unreached)
)]
#[kani::stub(hiperface_model::slave::fields::memory::FieldMemory::free, free_refused)]
#[kani::stub(hiperface_model::slave::fields::memory::FieldMemory::is_known, is_known_refused)]
#[kani::stub(hiperface_model::slave::fields::memory::FieldMemory::is_free_from, is_free_from_refused)]
fn contents_blind_store_data_one_byte() {
    contents_blind_command::<8>(0x4B, |_| true, false);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields) on two memories in any states (Kani: the memory reached only through its operations, any bytes read), every frame of Create Data Field (4Dh) at any time, with and without a UART fault.
/// Unwind 10, as `inductive_create_data_field` (`free` a stub: no loop over its
/// bytes). One step: `free` changing nothing (its answer: none), `read`, `write`,
/// `is_known` and `is_free_from` refused (`scripts/kani.sh --false-assertion`: `free`
/// refused too, which a field shrunk or deleted reaches: [`free_claimed_unreached`]).
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
#[kani::stub(hiperface_model::slave::fields::memory::FieldMemory::read, read_refused)]
#[kani::stub(hiperface_model::slave::fields::memory::FieldMemory::write, write_refused)]
#[cfg_attr(
    not(false_assertion),
    kani::stub(hiperface_model::slave::fields::memory::FieldMemory::free, free_changes_nothing)
)]
#[cfg_attr(
    false_assertion,
    kani::stub(hiperface_model::slave::fields::memory::FieldMemory::free, free_claimed_unreached)
)]
#[kani::stub(hiperface_model::slave::fields::memory::FieldMemory::is_known, is_known_refused)]
#[kani::stub(hiperface_model::slave::fields::memory::FieldMemory::is_free_from, is_free_from_refused)]
fn contents_blind_create_data_field() {
    contents_blind_command::<6>(0x4D, |_| true, false);
}

/// `read` answering any bytes where the real one answers something (its count of
/// them: `field_memory_any_read`, from any state), for the at most 128 bytes
/// `DataFields::read` asks for (asserted, not assumed: a longer read fails the
/// harness). Each call its own bytes.
#[allow(dead_code)] // used through `kani::stub`
fn read_any(_memory: &FieldMemory, start: usize, count: usize) -> Option<&[u8]> {
    assert!(count <= hiperface_model::frame::MAX_FIELD_BYTES, "a read of more than 128 bytes");
    let bytes: &'static [u8; hiperface_model::frame::MAX_FIELD_BYTES] = Box::leak(Box::new(kani::any()));
    crate::inductive::memory_holds(start, count).then(|| bytes.get(..count)).flatten()
}

/// `scripts/kani.sh --false-assertion contents_blind_store_data_one_byte` and
/// `_create_data_field`: the claim that the step never reaches the operation it does
/// reach, refused as the others are (so a refused operation the step reaches FAILs).
#[cfg(false_assertion)]
#[allow(dead_code)] // used through `kani::stub`
fn write_claimed_unreached(_memory: &mut FieldMemory, _start: usize, _data: &[u8]) -> bool {
    panic!("false assertion: Store Data never writes the field memory")
}

#[cfg(false_assertion)]
#[allow(dead_code)] // used through `kani::stub`
fn free_claimed_unreached(_memory: &mut FieldMemory, _from: usize, _to: usize) {
    panic!("false assertion: Create Data Field never frees field memory")
}

/// The operations a command's step must not reach: reaching one fails the harness.
#[allow(dead_code)] // used through `kani::stub`
fn read_refused(_memory: &FieldMemory, _start: usize, _count: usize) -> Option<&[u8]> {
    panic!("the step reads the field memory's contents")
}

#[allow(dead_code)] // used through `kani::stub`
fn write_refused(_memory: &mut FieldMemory, _start: usize, _data: &[u8]) -> bool {
    panic!("the step writes the field memory")
}

#[allow(dead_code)] // used through `kani::stub`
fn free_refused(_memory: &mut FieldMemory, _from: usize, _to: usize) {
    panic!("the step frees field memory")
}

#[allow(dead_code)] // used through `kani::stub`
fn is_known_refused(_memory: &FieldMemory, _i: usize) -> bool {
    panic!("the step asks which bytes the model knows")
}

#[allow(dead_code)] // used through `kani::stub`
fn is_free_from_refused(_memory: &FieldMemory, _start: usize) -> bool {
    panic!("the step asks whether memory is free")
}

/// The field memory's operations as the whole-step harnesses of the data field
/// commands take them (`#[kani::stub]`): they answer as the real ones do on the
/// memory the parts build (erased) and change nothing. Sound for what those
/// harnesses assert: the real ones change nothing but the `FieldMemory` they are
/// given (`&mut FieldMemory`, no other state), whose contents neither the invariant
/// (the table) nor the frame rules (the reply) read, save Read Data's reply, which
/// copies what `read` answers; no command both writes and reads them;
/// `field_memory_read`, `_write` and `_free` prove they answer as these do and never
/// panic.
#[allow(dead_code)] // used through `kani::stub`
fn write_answers_only(_memory: &mut FieldMemory, start: usize, data: &[u8]) -> bool {
    crate::inductive::memory_holds(start, data.len())
}

#[allow(dead_code)] // used through `kani::stub`
fn free_changes_nothing(_memory: &mut FieldMemory, _from: usize, _to: usize) {}

/// On erased memory, for the at most 128 bytes `DataFields::read` asks for.
#[allow(dead_code)] // used through `kani::stub`
fn read_erased(_memory: &FieldMemory, start: usize, count: usize) -> Option<&[u8]> {
    crate::inductive::erased_read_answer(start, count)
}

/// One frame of `command` with `data` data bytes from every state of a SEK37 that
/// satisfies the invariant (`inductive::Parts`, everything symbolic; at most 3 data
/// fields), with any address byte, data bytes and checksum byte, at any time, with
/// or without a UART fault: no panic, the invariant afterwards, the frame rules.
/// Unwind 10: the longest loop of a known length is `Slave::initialize`'s over the 9
/// initialization faults (+1) when the state is built (the profile's commands are a
/// constant, `CommandSet::all_for`: no loop over the command table's 23 rows, which
/// took 24 until 2026-11-27); the field table's loops over a count CBMC does not
/// know (at most 4 fields) and the checksum's over a reply of a length it does not
/// know are unrolled to the bound, and the unwinding assertions (on) show that 10 is
/// enough (a reply of more than 9 bytes needs more: Read Version, Read Data). Not
/// vacuous: the twin builds states satisfying the invariant from the same parts (it
/// fails if fewer than half its samples do), so the assumption holds for some of
/// them; a `kani::cover!` here would cost a second solver run as long as the proof.
/// `N`: the frame's length (address, command, data, checksum); an array of exactly
/// that length, as a slice of a longer one would have its loops unrolled as often
/// as the longer one allows.
fn inductive_command<const N: usize>(command: u8) {
    inductive_command_where::<N>(command, |_| true);
}

/// [`inductive_command`] for the frames `admit` takes (a harness whose domain is
/// part of the command's frames says which).
fn inductive_command_where<const N: usize>(command: u8, admit: fn(&[u8; N]) -> bool) {
    inductive_command_on::<N>(hiperface_model::profiles::sek37, command, admit);
}

/// [`inductive_command_where`] on a device of another profile.
fn inductive_command_on<const N: usize>(
    profile: fn() -> hiperface_model::Profile,
    command: u8,
    admit: fn(&[u8; N]) -> bool,
) {
    let (state, frame) = any_state_and_frame::<N>(profile, command, admit);
    assert!(crate::inductive::step_keeps_invariant(&state, &frame, kani::any(), kani::any()));
}

/// Any state of `profile` satisfying the invariant (`inductive::Parts`) and any frame of
/// `command` that `admit` takes (Store Data's count byte made to match its data): what
/// the whole-step harnesses start from.
fn any_state_and_frame<const N: usize>(
    profile: fn() -> hiperface_model::Profile,
    command: u8,
    admit: fn(&[u8; N]) -> bool,
) -> (hiperface_model::Slave, [u8; N]) {
    let parts: crate::inductive::Parts = kani::any();
    let (state, holds) = parts.state(profile());
    kani::assume(holds);
    let mut frame: [u8; N] = kani::any();
    if let Some(c) = frame.get_mut(1) {
        *c = command;
    }
    crate::inductive::count_store_data(&mut frame);
    kani::assume(admit(&frame));
    (state, frame)
}

/// Domain: every state of Legacy-SRS satisfying the invariant (at most 3 data fields), every frame of Set Position with Internal Track Synchronisation (63h) at any time, with and without a UART fault.
/// The legacy edition's own command (002:63h). Unwind 10, as on a SEK37.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_legacy_set_position_internal_sync() {
    inductive_command_on::<8>(hiperface_model::profiles::legacy_srs, 0x63, |_| true);
}

/// Domain: every state of Legacy-SRS satisfying the invariant (at most 3 data fields), every frame of Increment Counter (47h) at any time, with and without a UART fault.
/// A command whose behaviour differs in the legacy edition.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_legacy_increment_counter() {
    inductive_command_on::<3>(hiperface_model::profiles::legacy_srs, 0x47, |_| true);
}

/// Domain: every state of Legacy-SRS satisfying the invariant (at most 3 data fields), every frame of Set Serial Interface (57h) at any time, with and without a UART fault.
/// A command whose behaviour differs in the legacy edition.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_legacy_set_serial_interface() {
    inductive_command_on::<5>(hiperface_model::profiles::legacy_srs, 0x57, |_| true);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Store Data (4Bh) with 1 data byte at any time, with and without a UART fault.
/// The field memory's `write` as a stub ([`write_answers_only`]: the same answer,
/// no change; sound for what the step asserts, see there).
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
#[kani::stub(hiperface_model::slave::fields::memory::FieldMemory::write, write_answers_only)]
fn inductive_store_data_one_byte() {
    inductive_command::<8>(0x4B);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Read Data (4Ah) asking for 0 to 16 or more than 128 bytes at any time, with and without a UART fault.
/// Unwind 23: a reply of up to 16 data bytes is 22 bytes (field, offset and count
/// before the data, 000:T21), and the checksum's fold visits each; the requests for
/// 17 to 128 bytes, with replies up to 134 bytes, need a bound past 130, and at 136
/// the step was 2.5 M steps of symbolic execution (2026-11-27): their property is
/// sampled (`inductive_read_data_long`). The field memory's `read` as a stub
/// ([`read_erased`]; sound for what the step asserts, see there).
#[kani::proof]
#[kani::unwind(23)]
#[kani::solver(cadical)]
#[kani::stub(hiperface_model::slave::fields::memory::FieldMemory::read, read_erased)]
fn inductive_read_data() {
    inductive_command_where::<7>(0x4A, |f| crate::inductive::read_data_counted_short(f));
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Create Data Field (4Dh) at any time, with and without a UART fault.
/// The field memory's `free` as a stub ([`free_changes_nothing`]: no change; sound
/// for what the step asserts, see there).
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
#[kani::stub(hiperface_model::slave::fields::memory::FieldMemory::free, free_changes_nothing)]
fn inductive_create_data_field() {
    inductive_command::<6>(0x4D);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Read Counter (46h) at any time, with and without a UART fault.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_read_counter() {
    inductive_command::<3>(0x46);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Increment Counter (47h) at any time, with and without a UART fault.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_increment_counter() {
    inductive_command::<3>(0x47);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Reset Counter (49h) at any time, with and without a UART fault.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_reset_counter() {
    inductive_command::<4>(0x49);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Memory Status (4Eh) at any time, with and without a UART fault.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_memory_status() {
    inductive_command::<3>(0x4E);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Read Encoder Status (50h) at any time, with and without a UART fault.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_read_encoder_status() {
    inductive_command::<3>(0x50);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Read Type Label (52h) at any time, with and without a UART fault.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_read_type_label() {
    inductive_command::<3>(0x52);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Encoder Reset (53h) at any time, with and without a UART fault.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_encoder_reset() {
    inductive_command::<3>(0x53);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Temporarily Set Serial Interface (67h) at any time, with and without a UART fault.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_temporarily_set_serial_interface() {
    inductive_command::<4>(0x67);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Set Position with Synchronization (6Ah) at any time, with and without a UART fault.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_set_position_with_sync() {
    inductive_command::<8>(0x6A);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Sensor Adjustment (6Bh) at any time, with and without a UART fault.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_sensor_adjustment() {
    inductive_command::<5>(0x6B);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Read Synchronization Offset (6Ch) at any time, with and without a UART fault.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_read_sync_offset() {
    inductive_command::<3>(0x6C);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Read Position (42h) at any time, with and without a UART fault.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_read_position() {
    inductive_command::<3>(0x42);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Read Version (56h) at any time, with and without a UART fault.
// Unwind 41: its reply is 40 bytes (serial 9, firmware 20, date 8, 000:T31), and
// the checksum's fold visits each.
#[kani::proof]
#[kani::unwind(41)]
#[kani::solver(cadical)]
fn inductive_read_version() {
    inductive_command::<3>(0x56);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Set Serial Interface (57h) at any time, with and without a UART fault.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_set_serial_interface() {
    inductive_command::<5>(0x57);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Set Access Code (4Fh) at any time, with and without a UART fault.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_set_access_code() {
    inductive_command::<6>(0x4F);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Set Position (43h) at any time, with and without a UART fault.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_set_position() {
    inductive_command::<8>(0x43);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Read Analog Value (44h) at any time, with and without a UART fault.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_read_analog_value() {
    inductive_command::<4>(0x44);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Set Encoder Address (55h) at any time, with and without a UART fault.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_set_encoder_address() {
    inductive_command::<5>(0x55);
}

/// Domain: every state of SEK37 satisfying the invariant (at most 3 data fields), every frame of Data Field Status (4Ch) at any time, with and without a UART fault.
#[kani::proof]
#[kani::unwind(10)]
#[kani::solver(cadical)]
fn inductive_data_field_status() {
    inductive_command::<4>(0x4C);
}
