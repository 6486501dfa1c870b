//! The error stack behind the warning bit. // 000:2.3.4, 000:T27, DESIGN:stack

use crate::fault::FaultCode;
use crate::profile::StackOrder;

pub const STACK_DEPTH: usize = 4;

/// Up to four unread fault codes, each present once, oldest first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct ErrorStack {
    entries: [u8; STACK_DEPTH],
    len: u8,
}

impl ErrorStack {
    pub const fn new() -> ErrorStack {
        ErrorStack { entries: [0; STACK_DEPTH], len: 0 }
    }

    pub fn entries(&self) -> impl Iterator<Item = FaultCode> + '_ {
        // Over the whole array, taking `len`: a loop of at most STACK_DEPTH steps, which
        // a bounded model checker sees without knowing that `len` stays <= 4.
        self.entries.iter().take(self.len as usize).map(|b| FaultCode::decode(*b))
    }

    pub const fn len(&self) -> usize {
        self.len as usize
    }

    pub const fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The code in slot `i` (0 the oldest), if the stack holds that many.
    pub fn slot(&self, i: usize) -> Option<FaultCode> {
        self.entries.get(i).filter(|_| i < self.len as usize).map(|b| FaultCode::decode(*b))
    }

    pub fn contains(&self, code: FaultCode) -> bool {
        // Every slot visited, no early exit: a loop of STACK_DEPTH steps whatever the
        // length, which a bounded model checker bounds without knowing it.
        let mut found = false;
        for i in 0..STACK_DEPTH {
            found |= self.slot(i) == Some(code);
        }
        found
    }

    /// Store a code: once while unread; on overflow the oldest is dropped. 00h is never stored.
    pub fn push(&mut self, code: FaultCode) {
        if code == FaultCode::NoFault || self.contains(code) {
            return;
        }
        if self.len as usize == STACK_DEPTH {
            self.entries.copy_within(1.., 0);
            self.len -= 1;
        }
        self.entries[self.len as usize] = code.byte();
        self.len += 1;
    }

    /// Read Encoder Status: take one code, 00h when empty.
    pub fn pop(&mut self, order: StackOrder) -> FaultCode {
        if self.len == 0 {
            return FaultCode::NoFault;
        }
        let code = match order {
            StackOrder::OldestFirst => {
                let c = self.entries[0];
                self.entries.copy_within(1.., 0);
                c
            }
            StackOrder::NewestFirst => self.entries[self.len as usize - 1],
        };
        self.len -= 1;
        FaultCode::decode(code)
    }

    pub fn clear(&mut self) {
        self.len = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use FaultCode::*;

    #[test]
    fn dedup_overflow_and_order() {
        let mut s = ErrorStack::new();
        assert_eq!(s.pop(StackOrder::OldestFirst), NoFault);
        for c in [Temperature, Temperature, LedCurrent, Watchdog, InternalChecksum, AngularOffset] {
            s.push(c);
        }
        // Temperature stored once; five distinct codes: the oldest (Temperature) dropped.
        assert_eq!(s.len(), 4);
        let mut t = s;
        assert_eq!([t.pop(StackOrder::OldestFirst), t.pop(StackOrder::OldestFirst)], [LedCurrent, Watchdog]);
        assert_eq!(s.pop(StackOrder::NewestFirst), AngularOffset);
        s.push(NoFault);
        assert_eq!(s.len(), 3);
        s.clear();
        assert!(s.is_empty());
    }
}
