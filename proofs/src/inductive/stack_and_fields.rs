//! The error stack's and the data field table's parts of the invariant, each
//! inductive on its own (the harnesses `inductive_stack` and `inductive_data_fields`),
//! and the stack the parts of a state make.

use super::MAX_FIELDS;
use crate::invariant::{fields_invariant, stack_invariant};
use hiperface_model::profile::StackOrder;
use hiperface_model::slave::fields::{FieldStatus, FieldTable};
use hiperface_model::slave::stack::{ErrorStack, STACK_DEPTH};
use hiperface_model::FaultCode;

/// The stack the slave has after pushing the first `len` of `codes`, in order (00h
/// and a code already there are not stacked, `ErrorStack::push`). A loop of fixed
/// length, for Kani.
pub(super) fn stack_of(codes: [u8; STACK_DEPTH], len: u8) -> ErrorStack {
    let mut stack = ErrorStack::new();
    for (i, code) in codes.iter().enumerate() {
        if i < len as usize {
            stack.push(FaultCode::decode(*code));
        }
    }
    stack
}

/// The error stack's part of the invariant is inductive on its own: from any stack
/// that satisfies it (`codes` pushed in order, the first `len`: every stack of at most
/// four distinct codes other than 00h is one), one operation the slave performs on it
/// (`op`: push `code`, pop oldest first, pop newest first, clear) keeps it, and the
/// warning bit the slave derives from it (`is_empty`) says whether a code is left.
/// // 000:T27, 000:2.3.4
pub fn stack_step_keeps_invariant(codes: [u8; STACK_DEPTH], len: u8, op: u8, code: u8) -> bool {
    let mut stack = stack_of(codes, len);
    if stack_invariant(&stack).is_err() {
        return true;
    }
    let popped = match op % 4 {
        0 => {
            stack.push(FaultCode::decode(code));
            // A code pushed is on the stack afterwards (a full stack drops its oldest),
            // unless it is 00h, never stored.
            code == 0 || stack.contains(FaultCode::decode(code))
        }
        1 => stack.pop(StackOrder::OldestFirst) != FaultCode::NoFault || stack.is_empty(),
        2 => stack.pop(StackOrder::NewestFirst) != FaultCode::NoFault || stack.is_empty(),
        _ => {
            stack.clear();
            stack.is_empty()
        }
    };
    // The warning bit's source agrees with the slots: empty exactly when none holds a code.
    let mut none = true;
    for i in 0..STACK_DEPTH {
        none &= stack.slot(i).is_none();
    }
    popped && stack_invariant(&stack).is_ok() && stack.is_empty() == none
}

/// A data field table and one operation on it, as plain values (see
/// [`fields_step_keeps_invariant`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(kani, derive(kani::Arbitrary))]
pub struct FieldsStep {
    pub statuses: [u8; MAX_FIELDS],
    pub count: u8,
    pub capacity: u8,
    pub op: u8,
    pub number: u8,
    pub status: u8,
}

/// The data field table's part of the invariant is inductive on its own: from any
/// table of at most [`MAX_FIELDS`] fields on `capacity` blocks that satisfies it, one
/// operation Create Data Field performs on it (`op`: create a field with `status`,
/// change field `number` to `status` (attributes, or the last field's size), delete
/// the last) keeps it; an operation refused leaves the table as it was. Store Data
/// (`DataFields::write`) writes contents only, never the table. // 000:2.4.2, 000:T24,
/// DESIGN:fields
pub fn fields_step_keeps_invariant(step: &FieldsStep) -> bool {
    let FieldsStep { statuses, count, capacity, op, number, status } = *step;
    let count = (count as usize).min(MAX_FIELDS);
    let mut fields = FieldTable::from_table(capacity, &statuses, count);
    if fields_invariant(&fields, capacity).is_err() {
        return true;
    }
    let done = match op % 3 {
        0 => fields.create(FieldStatus(status)),
        1 => fields.modify(number, FieldStatus(status)),
        _ => fields.delete_last(),
    };
    // A fixed loop (for Kani), no allocation.
    let mut unchanged = fields.count() as usize == count;
    for (i, s) in statuses.iter().enumerate() {
        if i < count {
            unchanged &= fields.status(i as u8).map(|f| f.0) == Some(s | FieldStatus::EXISTS);
        }
    }
    (done || unchanged) && fields_invariant(&fields, capacity).is_ok()
}
