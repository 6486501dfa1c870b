//! The clause registry: every rule the model implements or the harness grades, with a
//! short quotation of the document it comes from.
//!
//! A clause id is `DOC:PLACE`: `DOC` is the seed file's number (000 = the current
//! HIPERFACE specification, 001 = Kübler S36 manual, 002 = the legacy SICK-STEGMANN
//! description), `PLACE` is a section (`2.3.3`) or a table (`T13`). `DESIGN` marks a
//! decision of this project where the documents are silent (docs/src/design.md).
//!
//! Clauses are typed: only this module constructs them. A [`Normative`] clause is a
//! rule of 000 or 002 that binds a device of the editions it names; only a normative
//! clause can carry a FAIL (see `oracle::Grade`). Decisions and informative sources
//! (001's examples, third-party manuals) carry NON-STRICT at most.

use crate::settings::Edition;
use core::fmt;

/// What a clause's authority is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Force {
    /// A rule of the specification (000) or the legacy description (002).
    Normative,
    /// A "should" or "strongly recommended" of the specification: NON-STRICT at most.
    Recommended,
    /// A decision of this project where the documents are silent.
    Decision,
    /// An example or a third party's reading (001, 003, 004).
    Informative,
}

/// Which editions a normative clause binds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Binds {
    Both,
    Current,
    Legacy,
}

/// One clause of the registry. Only this module constructs clauses.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Clause {
    id: &'static str,
    quote: &'static str,
    force: Force,
    binds: Binds,
}

impl Clause {
    /// The clause itself (so that `X.clause()` works for every registry constant,
    /// normative or not).
    pub const fn clause(self) -> Clause {
        self
    }

    pub const fn id(self) -> &'static str {
        self.id
    }

    pub const fn quote(self) -> &'static str {
        self.quote
    }

    pub const fn force(self) -> Force {
        self.force
    }

    /// The clause as a rule that can carry a FAIL, if it is one.
    pub const fn normative(self) -> Option<Normative> {
        match self.force {
            Force::Normative => Some(Normative(self)),
            _ => None,
        }
    }

    /// The clause as a rule that binds a device of `edition`, if it is one.
    pub fn binding(self, edition: Edition) -> Option<Normative> {
        self.normative().filter(|n| n.binds(edition))
    }
}

impl fmt::Debug for Clause {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.id)
    }
}

impl fmt::Display for Clause {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.id)
    }
}

/// Compare with an id, as reports and tests print it.
impl PartialEq<&str> for Clause {
    fn eq(&self, other: &&str) -> bool {
        self.id == *other
    }
}

impl PartialEq<&str> for Normative {
    fn eq(&self, other: &&str) -> bool {
        self.0 == *other
    }
}

/// A normative clause: a rule of 000 or 002 whose violation is a FAIL.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Normative(Clause);

impl Normative {
    pub const fn clause(self) -> Clause {
        self.0
    }

    pub const fn id(self) -> &'static str {
        self.0.id
    }

    /// Whether the rule binds a device of `edition` (000's rules that 002 does not
    /// share bind current devices only, and the other way round).
    pub fn binds(self, edition: Edition) -> bool {
        matches!(
            (self.0.binds, edition),
            (Binds::Both, _) | (Binds::Current, Edition::Current) | (Binds::Legacy, Edition::Legacy)
        )
    }
}

impl From<Normative> for Clause {
    fn from(n: Normative) -> Clause {
        n.0
    }
}

impl fmt::Debug for Normative {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.0.id)
    }
}

impl fmt::Display for Normative {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.0.id)
    }
}

macro_rules! clauses {
    ($( [$($kind:tt)+] $name:ident = $id:literal : $quote:literal ;)*) => {
        $( clauses!(@one [$($kind)+] $name $id $quote); )*
        /// Every clause, in document order.
        pub const CLAUSES: &[Clause] = &[ $( clauses!(@any [$($kind)+] $name) ),* ];
    };
    (@one [normative $binds:ident] $name:ident $id:literal $quote:literal) => {
        #[doc = $quote]
        pub const $name: Normative =
            Normative(Clause { id: $id, quote: $quote, force: Force::Normative, binds: Binds::$binds });
    };
    (@one [$force:ident] $name:ident $id:literal $quote:literal) => {
        #[doc = $quote]
        pub const $name: Clause = Clause { id: $id, quote: $quote, force: Force::$force, binds: Binds::Both };
    };
    (@any [normative $binds:ident] $name:ident) => { $name.0 };
    (@any [$force:ident] $name:ident) => { $name };
}

clauses! {
    [normative Both] UART_SETTINGS = "000:T4": "Data rate 9600 Baud default, can be programmed to 600 ... 38400 Baud; 8 data bits, LSB first; 1 start bit; 1 stop bit; parity even (odd, even, none).";
    [normative Both] NO_UNSOLICITED = "000:2.2.1/slave": "The Slave will never initiate communication on its own.";
    [normative Both] DEFAULT_PARITY = "000:2.2.1": "The actually implemented default parity check always conformed to an \"Even\" parity definition.";
    [normative Both] FRAME_TIMING = "000:2.2.2": "If the Slave receives no further character within the timeout condition the message will be considered terminated and processed.";
    [normative Current] TIMEOUT = "000:2.2.2/timeout": "The timeout condition can be programmed to be either 22 s/Data rate or 55 s/Data rate (default, i.e. 5.73 ms for 9600 Baud).";
    [normative Current] REPLY_END = "000:2.2.2/reply-end": "The end of the Slave transmission is also indicated by a pause of at least the length of the timeout condition.";
    [normative Both] ADDRESS = "000:T5": "Bits 0...4 address value, bit 5 fixed 0, bit 6 fixed 1, bit 7 fixed 0. The default address is 0 (40h).";
    [normative Both] BROADCAST = "000:2.3.1": "A broadcast address (FFh) with which a Master can address all bus-linked Slaves; each Slave will acknowledge with their specific address.";
    [normative Both] COMMAND_BYTE = "000:T6": "Bits 0...5 command value, bit 6 fixed 1, bit 7 error bit.";
    [normative Both] CHECKSUM = "000:2.3.3": "The checksum is defined through an XOR operation on all frame bytes including address.";
    [normative Both] CHECKSUM_EXAMPLES = "000:T7": "40h 42h -> 02h; 40h 4Eh 70h 00h -> 7Eh.";
    [normative Both] WARNING_BIT = "000:2.3.4": "The Slave will issue the warning bit with each following command response until the Master has read out the error code (with command 50h) or performed a Slave reset (command 53h).";
    [normative Both] ERROR_RESPONSE = "000:2.3.4/error": "The error response contains the status command value 50h followed by an appropriate error code; with a warning in parallel the command value is D0h.";
    [normative Current] POSITION_LOCK = "000:2.3.4/critical": "If the Slave detects error conditions critical to position measurement further Master position requests will be answered with error messages until the Slave is reset.";
    [normative Both] COMMAND_DEFINITION = "000:T8": "Response time: maximum response time of Slave after Master request timeout; does not include transmission times and protocol timeout.";
    [normative Current] STATE_MACHINE = "000:T9": "Initialization (no UART, 100 ms, at most 200 ms) -> Default Communication (9600, even, 5x timeout) -> any request: Operational (default); none until 900 ms: change of settings (no UART) -> 1100 ms: Operational (user-defined).";
    [normative Both] COMMON_ERRORS = "000:2.4.2": "For all commands: parity error (09h), checksum error (0Ah), unknown command (0Bh), wrong command length (0Ch).";
    [normative Both] COMMANDS = "000:T10": "User command summary: identifiers and maximum response times.";
    [normative Both] READ_POSITION = "000:T12": "Read Position 42h: no master data; slave data absolute position as unsigned 32 bit, MSB first.";
    [normative Both] POSITION_RESOLUTION = "000:T11": "The absolute position has a resolution of 5 bits per sine/cosine period in all Slaves.";
    [normative Both] SET_POSITION = "000:T13": "Set Position 43h: preset (4 bytes) + Code0; any preset within the measuring range; must be called at standstill.";
    [normative Both] READ_ANALOG = "000:T15": "Read Analog Value 44h: CHANNEL selector; reply CHANNEL + 16 bit sensor value; 0Dh for a wrong argument.";
    [normative Current] ANALOG_SOURCES = "000:T14": "48h encoder temperature in 1 degC steps, signed 16 bit; F0h legacy temperature in 2.048 degC steps: Temperature = ((F0h)+40)/2.048.";
    [normative Both] READ_COUNTER = "000:T16": "Read Counter 46h: 24 bit unsigned counter.";
    [normative Both] INCREMENT_COUNTER = "000:T17": "Increment Counter 47h: increments the non-volatile counter by one; errors 05h, 06h, 08h.";
    [normative Both] RESET_COUNTER = "000:T18": "Reset Counter 49h: writes 0; needs Code0.";
    [normative Both] DATA_FIELDS = "000:2.4.2/data-fields": "Data fields of 16 to 128 bytes in multiples of 16, consecutive numbers from 0, linked to Code0...Code3, read-only or write-enabled; only the last field can change size; fields can be deleted.";
    [normative Current] EXTENDED_TYPE_LABEL = "000:T20": "Extended Type Label: virtual data field FFh, at least 64 bytes, XOR checksum at offset 00h, read-only, no access code, not counted as a data field.";
    [normative Both] READ_DATA = "000:T21": "Read Data 4Ah: field, offset, count (1...128), access code; offset + count must not exceed the field size.";
    [normative Both] STORE_DATA = "000:T22": "Store Data 4Bh: field, offset, count, access code, data; offset + count must not exceed the field size; not to read-only fields.";
    [normative Both] FIELD_STATUS = "000:T23": "Data Field Status 4Ch: bits 0-2 size/16-1, bit 3 code enabled, bits 4-5 code number, bit 6 write-enabled, bit 7 exists.";
    [normative Both] CREATE_FIELD = "000:T24": "Create Data Field 4Dh: new number = next available; bit 7 = 1 create/modify, 0 delete; delete or resize only the last field; the access code byte must correspond to the field's code even if disabled.";
    [normative Both] MEMORY_STATUS = "000:T25": "Memory Status 4Eh: free user memory in 16 byte blocks, number of data fields.";
    [normative Both] SET_ACCESS_CODE = "000:T26": "Set Access Code 4Fh: code number 00h...03h, old code, new code; default 55h.";
    [normative Both] READ_ENCODER_STATUS = "000:T27": "Read Encoder Status 50h: one active warning or error per request from the stack of four; stored once until read; oldest deleted on overflow; 00h when none.";
    [normative Both] READ_TYPE_LABEL = "000:T28": "Read Type Label 52h: UART settings, encoder type, memory size in 16 byte blocks, option code.";
    [normative Both] SETTINGS_BYTE = "000:T28/settings": "Bits 0-2 data rate 000=600 ... 110=38400; bit 3 not implemented; bits 4-5 00 none, 10 even, 11 odd; bit 6 timeout 0 = 2*11, 1 = 5*11 bit times; bit 7 1 = standard slave. Default E4h.";
    [normative Both] ENCODER_RESET = "000:T29": "Encoder Reset 53h: no response; executed after the timeout of the request; respond again after 100 ms initialization plus that timeout.";
    [normative Both] RESET_KEEPS = "000:T29/keeps": "Configuration data like Slave address and interface settings are not changed by an Encoder Reset.";
    [normative Current] SET_ADDRESS = "000:T30": "Set Encoder Address 55h: new address 40h...5Fh + Code0; the response already uses the new address.";
    [normative Current] READ_VERSION = "000:T31": "Read Version 56h: 37 bytes: serial number (9), firmware version (20, trailing 00h), firmware date (8).";
    [normative Both] SET_SERIAL = "000:T32": "Set Serial Interface 57h: settings byte + Code0; new settings used only after an encoder reset or power cycle.";
    [normative Current] TEMP_SERIAL = "000:T33": "Temporarily Set Serial Interface 67h: applied directly without storage; the response still uses the previous settings; discarded on reset.";
    [normative Current] SET_POSITION_SYNC = "000:T34": "Set Position with Synchronization 6Ah: the preset is rounded to the next value with zero phase shift; the reply carries the preset actually used.";
    [normative Current] SENSOR_ADJUSTMENT = "000:T35": "Sensor Adjustment 6Bh: one implementation-specific option byte + Code0; reply option code + status.";
    [normative Current] READ_SYNC_OFFSET = "000:T36": "Read Synchronization Offset 6Ch: phase shift 0...31 to be added to the current position value.";
    [normative Both] FAULT_GROUPS = "000:T37": "Protocol and data errors are answered and not stacked; position errors are answered, further ones stacked; others are stored in the error stack.";
    [normative Both] INIT_FAULTS = "000:T38-T46": "Initialization faults are stored in the error stack along with the internal checksum error (06h); 01h, 02h, 04h lock position output (02h).";
    [normative Both] I2C_BUS = "000:T43": "Internal I2C bus not operational: the Slave could not establish communication to its nonvolatile memory.";
    [normative Both] NV_LOCK = "000:T44": "If an internal checksum error is detected at start-up no command will be executed that reads critical or writes any data to nonvolatile memory.";
    [normative Current] COUNTER_OVERFLOW = "000:T46": "The counter stays at its maximum value FFFFFFh until it is reset; increment answers 08h.";
    [normative Both] PARITY_ERROR = "000:T47": "A UART fault in a Master request: the message will not be parsed further.";
    [normative Both] CHECKSUM_ERROR = "000:T48": "A checksum fault in a Master request: the message will not be parsed further.";
    [normative Both] UNKNOWN_COMMAND = "000:T49": "A Master request message with an unknown command value.";
    [normative Both] WRONG_LENGTH = "000:T50": "A Master request message with an invalid number of message bytes.";
    [normative Both] WRONG_ARGUMENT = "000:T51": "An invalid value in one of the command argument bytes.";
    [normative Both] READ_ONLY_FIELD = "000:T52": "A Store Data request to a read-only data field or to the Extended Type Label.";
    [normative Both] WRONG_ACCESS_CODE = "000:T53": "The transmitted access code byte was wrong.";
    [normative Both] OUT_OF_MEMORY = "000:T54": "Create Data Field does not fit in the remaining memory, or targets the Extended Type Label.";
    [normative Both] WRONG_OFFSET = "000:T55": "Read or write with an offset outside the data field size (64 bytes for the Extended Type Label).";
    [normative Both] WRONG_FIELD_NUMBER = "000:T56": "Invalid data field number; create with the delete bit set; resize of a field that is not the last one.";
    [normative Both] LED_CURRENT = "000:T58": "Transmitter current critical (1Dh), checked prior to every Slave response message.";
    [normative Both] ANALOG_MONITORING = "000:T57": "Value monitoring analog signals (1Ch): significant signal faults in the analog sine/cosine signals; the position output will not be locked.";
    [normative Both] TEMPERATURE = "000:T59": "Encoder temperature critical (1Eh): indicated with the warning bit, checked prior to every response.";
    [normative Both] SPEED = "000:T60": "Speed too high (1Fh): invalid speed during Read Position, or shaft motion during Set Position (not processed).";
    [normative Both] POSITION_FAULTS = "000:T61-T68": "Position faults 20h...24h are answered on position commands; 22h, 24h and linear 20h lock position output (02h).";
    [normative Both] QUADRATURE = "000:T72": "Quadrature counting: the counter changes by one on each edge of the sine and cosine comparator signals, direction by the other signal's level.";
    [normative Both] INTERPOLATION = "000:3.2.4": "Fine-angle interpolation: the angle within a period from the arc tangent of the sine and cosine values.";
    [normative Both] SYNCHRONIZATION = "000:3.2.5": "Position synchronization: the two LSBs of the counter and of the absolute position's period bits must agree within 50 % of a period; the table gives the correction.";
    [normative Both] FAULT_REACTION = "000:T74": "Fault code, group, severity and controller response; unknown codes get the worst-case reaction.";
    [normative Both] MASTER_CYCLE = "000:2.2/cycle": "Each data transmission consists of a Master request frame followed by a Slave response frame. The Master transmission must be terminated through a timeout condition after the last byte is transmitted.";
    [normative Both] MASTER_CHARACTER_GAP = "000:2.2.2/master-gap": "Each character of the Master transmission must be followed by a subsequent character within the timeout condition.";
    [normative Both] MASTER_PAUSE = "000:2.2.2/master-pause": "Accordingly the end of a Master transmission must be followed by a pause of at least the length of the timeout condition.";
    [normative Both] MASTER_FRAME = "000:2.3/master": "Each frame contains an address byte, command, and optionally data bytes of varying length and a trailing checksum to detect transmission errors. This specification applies both for Master and Slave transmissions.";
    [normative Both] MASTER_NO_FAULTS = "000:2.3.4/master": "Faults are always only communicated from Slave to Master.";
    [normative Both] MASTER_RESET_WAIT = "000:T29/master": "A HIPERFACE Master must wait for this time plus the initialization time of 100 ms before communication can resume.";
    [normative Both] MASTER_START_UP = "000:3.3.1": "At power-up of the encoder the drive controller has to follow the state machine of the HIPERFACE Slave. Depending on required communication settings the drive controller must wait for the Default Communication Phase to pass.";
    [Recommended] MASTER_READ_STATUS = "000:3.3.1/status": "It is strongly recommended to read the Slave status after a power-on and react according to potential fault indications.";
    [Recommended] MASTER_WARNING = "000:2.3.4/warning": "The Slave will issue the warning bit with each following command response until the Master has read out the error code (with command 50h) or performed a Slave reset (command 53h).";
    [Recommended] MASTER_FAULT_REACTION = "000:3.3.4": "In a second step it is recommended to refine drive controller actions based on individual fault codes as lined out in the following table.";
    [Recommended] MASTER_EXTENDED_TYPE_LABEL = "000:T19/master": "Masters have to implement the corresponding encoder parameters for a given code during design. Slaves that only implement the Extended Type Label have to use the type code FFh.";
    [Recommended] MASTER_CYCLIC = "000:3.2.2/cyclic": "As the HIPERFACE Slave only issues fault indications upon command requests a sufficient cyclic request should be implemented in the drive software. If no other information is required the command Read Position should be used to poll fault indications.";
    [Recommended] MASTER_UNKNOWN_CODE = "000:3.3.4/unknown": "It is expected that a HIPERFACE Master can only react with the worst-case fault reaction to unknown fault codes (i.e. motor stop).";
    [Informative] S36_EXAMPLES = "001:5.1.4": "Worked request/response examples of the Kuebler Sendix S36.";
    [normative Legacy] LEGACY_TIMEOUT = "002:timing": "TIMEOUT programmable, 11/baud rate or 44/baud rate = default.";
    [normative Legacy] LEGACY_DEFAULT_WINDOW = "002:57h": "After power-up each MFB is set to the default values for about 1 second; a plausible message keeps this setting.";
    [normative Legacy] LEGACY_COUNTER = "002:47h": "Any overflow is shown by the ERROR bit.";
    [normative Legacy] LEGACY_SET_POSITION_SYNC = "002:63h": "Set position with internal track synchronisation 63h: position offset + Code0; the MFB calculates internal angle offsets.";
    [normative Legacy] LEGACY_ERROR_CODES = "002:50h": "The actual available errors vary according to MFB type and are always given on the data sheet.";
    [normative Legacy] LEGACY_VERSION = "002:56h": "The 9-digit serial number, the firmware version of up to 20 characters and the 8-digit firmware date in the DD.MM.YY format.";
    [Informative] DATAFIELD_EXAMPLE = "002:example": "Example data field definition: address 40h, codes 55h, 128 bytes free.";
    [Decision] CHECK_ORDER = "DESIGN:order": "1) not own address nor FFh: silent; 2) UART fault 09h; 3) < 3 bytes 0Ch; 4) checksum 0Ah; 5) unknown command 0Bh; 6) length 0Ch; 7) argument 0Dh; 8) access code 0Fh; 9) state and data checks.";
    [Decision] STACK_POLICY = "DESIGN:stack": "4 entries, a code present once while unread, overflow drops the oldest, 50h returns the oldest first, 00h when empty, 53h clears it; an Others condition that holds is stacked before 50h reads the stack.";
    [Decision] FIELD_POLICY = "DESIGN:fields": "Sizes and free memory in 16 byte blocks; new field contents read FFh; delete and resize only the last field; FFh is the Extended Type Label.";
    [Decision] POWER_UP_POLICY = "DESIGN:power-up": "A request addressed to the slave in the default window keeps the default settings until the next reset.";
    [Decision] POSITION_POLICY = "DESIGN:position": "offset = preset - raw (mod range); 6Ah keeps the raw 5 LSBs, nearest value, ties downward; 6Ch returns (-offset) mod 32.";
    [Decision] LEGACY_TIMEOUT_READING = "DESIGN:legacy-timeout": "002's 11/44 bit times are the pause from a stop bit to the next start bit (000:2.2.2 note): a receiver counting from character ends times out after 22/55; a legacy reply may start after a pause of 11/44.";
    [Decision] TYPE_LABEL_SETTINGS = "DESIGN:52h": "Read Type Label reports the stored settings byte.";
    [Decision] MASTER_REPLY_WINDOW = "DESIGN:reply-window": "A master leaves the reply window open (the request's timeout plus the command's maximum response time) before its next request, and a pause of the timeout after a reply's end; otherwise it may talk over a late reply.";
}

/// Look a clause up by id.
pub fn lookup(id: &str) -> Option<Clause> {
    CLAUSES.iter().copied().find(|c| c.id == id)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_are_unique_and_well_formed() {
        for (i, a) in CLAUSES.iter().enumerate() {
            let (doc, place) = a.id.split_once(':').expect("DOC:PLACE");
            assert!(matches!(doc, "000" | "001" | "002" | "003" | "004" | "DESIGN"), "{}", a.id);
            // Only the specification and the legacy description are normative (or
            // recommend); only decisions are DESIGN's.
            let spec = matches!(doc, "000" | "002") && a.id != "002:example";
            let ok = match a.force {
                Force::Normative | Force::Recommended => spec,
                Force::Decision => doc == "DESIGN",
                Force::Informative => !spec && doc != "DESIGN",
            };
            assert!(ok, "{}: {:?}", a.id, a.force);
            assert!(!place.is_empty() && !a.quote.is_empty(), "{}", a.id);
            for b in &CLAUSES[i + 1..] {
                assert_ne!(a.id, b.id, "duplicate clause id");
            }
        }
        assert_eq!(lookup("000:2.3.3"), Some(CHECKSUM.clause()));
        assert!(lookup("000:T999").is_none());
    }

    #[test]
    fn editions_bind_their_own_rules() {
        assert!(CHECKSUM.binds(Edition::Legacy) && CHECKSUM.binds(Edition::Current));
        assert!(READ_VERSION.binds(Edition::Current) && !READ_VERSION.binds(Edition::Legacy));
        assert!(LEGACY_VERSION.binds(Edition::Legacy) && !LEGACY_VERSION.binds(Edition::Current));
        assert_eq!(CHECK_ORDER.normative(), None, "a decision never carries a FAIL");
        assert_eq!(S36_EXAMPLES.normative(), None, "nor does a third party's example");
        assert_eq!(READ_VERSION.clause().binding(Edition::Legacy), None);
        assert_eq!(CHECKSUM.clause().binding(Edition::Legacy), Some(CHECKSUM));
    }
}
