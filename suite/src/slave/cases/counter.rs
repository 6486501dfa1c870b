//! The user counter: read, increment, reset. // 000:T16-T18

use super::{always, case, code0};
use crate::slave::Case;
use hiperface_model::Request;

pub const READ: Case = case!("counter.read", "Read Counter", [READ_COUNTER], Nothing, always, |c| c
    .request(Request::ReadCounter)
    .map(drop));

pub const INCREMENT: Case = case!(
    "counter.increment",
    "Increment Counter counts; Reset Counter needs Code0",
    [INCREMENT_COUNTER, RESET_COUNTER],
    CounterChange,
    always,
    |c| {
        let code0 = code0(c);
        c.request(Request::ReadCounter)?;
        c.request(Request::IncrementCounter)?;
        c.request(Request::ReadCounter)?;
        c.request(Request::ResetCounter { code0: !code0 })?;
        c.request(Request::ResetCounter { code0 })?;
        c.request(Request::ReadCounter).map(drop)
    }
);
