//! A frame as a byte diagram: a cell per byte, the row beneath naming the bytes by the
//! model's request and reply types, the checksum worked out (000:2.3.3) and a reply's
//! warning bit spelled out (000:2.3.4).

use super::bits;
use crate::report::escape;
use crate::vectors::{parse_hex, VectorStep};
use hiperface_model::{checksum, CommandId, Request, RequestFrame, Response, ResponseFrame};
use std::fmt::Write as _;

#[derive(Clone, Copy)]
pub(super) enum Role {
    Request,
    /// A reply to a request of this command.
    Reply(CommandId),
}

pub(super) fn step_html(step: &VectorStep) -> String {
    let request = parse_hex(&step.request).unwrap_or_default();
    let to = CommandId::of_frame(&request);
    let reply = match step.response.as_deref().map(parse_hex) {
        Some(Ok(r)) => frame_html(&r, Role::Reply(to), "reply", &[]),
        _ => "<div class=\"hf-f\"><p class=\"hf-none\"><b>reply</b>: none, the slave stays silent</p></div>".into(),
    };
    format!("<div class=\"hf-step\">\n{}\n{reply}\n</div>\n", frame_html(&request, Role::Request, "request", &[]))
}

/// A frame as a byte diagram, its checksum worked out and, in a reply, the warning bit
/// spelled out. `marked`: the bytes to mark as wrong (an erratum's printed bytes).
pub(super) fn frame_html(bytes: &[u8], role: Role, caption: &str, marked: &[bool]) -> String {
    let labels = match role {
        Role::Request => request_labels(bytes),
        Role::Reply(to) => reply_labels(bytes, to),
    };
    let n = bytes.len();
    let sum_ok = n >= 3 && checksum::xor(&bytes[..n - 1]) == bytes[n - 1];
    let mut s = String::from("<div class=\"hf-f\">");
    // Sixteen bytes to a table, each row of bytes with its row of names; the frame's
    // caption on the first.
    for start in (0..n).step_by(16) {
        let end = (start + 16).min(n);
        s.push_str("<table class=\"hf-frame\">");
        if start == 0 {
            let _ = write!(s, "<caption>{caption}</caption>");
        }
        s.push_str("\n<tr>");
        for (i, byte) in bytes.iter().enumerate().take(end).skip(start) {
            let kind = match i {
                0 => "hf-addr",
                1 => "hf-cmd",
                i if i + 1 == n && n >= 3 => "hf-sum",
                _ => "hf-data",
            };
            let bad = marked.get(i).copied().unwrap_or(false) || (i + 1 == n && n >= 3 && !sum_ok);
            let class = if bad { format!("{kind} hf-bad") } else { kind.to_string() };
            let _ = write!(s, "<td class=\"hf-b {class}\">{byte:02X}</td>");
        }
        s.push_str("</tr>\n<tr>");
        let mut i = start;
        while i < end {
            let span = labels[i..end].iter().take_while(|l| **l == labels[i]).count();
            let colspan = if span > 1 { format!(" colspan=\"{span}\"") } else { String::new() };
            let _ = write!(s, "<td class=\"hf-l\"{colspan}>{}</td>", escape(&labels[i]));
            i += span;
        }
        s.push_str("</tr>\n</table>\n");
    }
    if n >= 3 {
        let body: Vec<String> = bytes[..n - 1].iter().map(|b| format!("{b:02X}h")).collect();
        let xor = checksum::xor(&bytes[..n - 1]);
        let carried =
            if sum_ok { String::new() } else { format!("; the frame carries <b>{:02X}h</b>: wrong", bytes[n - 1]) };
        let _ =
            writeln!(s, "<p class=\"hf-xor\">checksum: <code>{} = {xor:02X}h</code>{carried}</p>", body.join(" XOR "));
    } else {
        let bytes = if n == 1 { "1 byte" } else { "2 bytes" };
        let _ =
            writeln!(s, "<p class=\"hf-xor\">{bytes}: too short for a checksum after the address and the command</p>");
    }
    for line in meanings(bytes, role, &labels) {
        let _ = writeln!(s, "<p class=\"hf-bits-said\">{}</p>", escape(&line));
    }
    if let (Role::Reply(_), Some(&command)) = (role, bytes.get(1)) {
        if command & 0x80 != 0 {
            let id = CommandId::decode(command & 0x7F);
            let what = if id == CommandId::ReadEncoderStatus && n == 4 {
                "50h, the error response (000:2.3.4/error)".to_string()
            } else {
                id.to_string()
            };
            let _ = writeln!(
                s,
                "<p class=\"hf-warn\">command byte {command:02X}h = 80h + {what}: bit 7 is the <b>warning bit</b> \
                 (000:2.3.4), set until the master reads the error stack with 50h or resets the slave with 53h</p>"
            );
        }
    }
    s.push_str("</div>");
    s
}

/// What the bytes of a frame that pack bits or count blocks say, by the model's
/// decoders (000:T23-T25, T28, T32, T33).
pub(super) fn meanings(bytes: &[u8], role: Role, labels: &[String]) -> Vec<String> {
    use bits::Packed;
    let command = CommandId::of_frame(bytes);
    let mut out = Vec::new();
    for (byte, label) in bytes.iter().zip(labels) {
        let packed = match (label.as_str(), role) {
            ("settings", _) => Some(Packed::Settings),
            ("status", Role::Request) if command == CommandId::CreateDataField => Some(Packed::CreateRequest),
            ("status", Role::Reply(CommandId::CreateDataField)) => Some(Packed::CreateReply),
            ("status", Role::Reply(CommandId::DataFieldStatus)) => Some(Packed::FieldStatus),
            _ => None,
        };
        let said = match (packed, label.as_str()) {
            (Some(p), _) => format!("{label} {}", bits::spelled(p, *byte)),
            (None, "free 16-byte blocks") => {
                format!(
                    "free user memory {byte:02X}h = {byte} blocks of 16 bytes = {} bytes (000:T25)",
                    *byte as usize * 16
                )
            }
            (None, "memory, 16-byte blocks") => {
                format!(
                    "total memory {byte:02X}h = {byte} blocks of 16 bytes = {} bytes (000:T28)",
                    *byte as usize * 16
                )
            }
            (None, "data fields") => format!("{byte} data fields exist (000:T25)"),
            (None, "encoder type") if *byte == 0xFF => {
                "encoder type FFh: an Extended Type Label is available, read it as data field FFh (000:T28, 000:T19)"
                    .to_string()
            }
            (None, "encoder type") => format!("encoder type {byte:02X}h: a specific encoder type (000:T28)"),
            _ => continue,
        };
        out.push(said);
    }
    out
}

/// The address, the command and the checksum, and the data bytes between them.
pub(super) fn frame_labels(bytes: &[u8], command: &str, data: Option<Vec<String>>) -> Vec<String> {
    let n = bytes.len();
    let mut out = Vec::with_capacity(n);
    if let Some(&a) = bytes.first() {
        out.push(if a == 0xFF { "broadcast address".to_string() } else { "address".to_string() });
    }
    if n >= 2 {
        out.push(command.to_string());
    }
    if n >= 3 {
        let len = n - 3;
        match data.filter(|d| d.len() == len) {
            Some(d) => out.extend(d),
            None => out.extend((1..=len).map(|i| format!("data {i}"))),
        }
        out.push("checksum".into());
    }
    out
}

/// `bytes` with the checksum it should carry: the layout of the data does not depend on
/// it, so a frame with a wrong checksum is named as the right one would be.
pub(super) fn sealed(bytes: &[u8]) -> Vec<u8> {
    let mut b = bytes.to_vec();
    if let Some((last, body)) = b.split_last_mut() {
        *last = checksum::xor(body);
    }
    b
}

pub(super) fn request_labels(bytes: &[u8]) -> Vec<String> {
    let data = RequestFrame::decode(&sealed(bytes))
        .ok()
        .map(|f| request_fields(&f.request).into_iter().map(str::to_string).collect());
    let command = match CommandId::of_frame(bytes) {
        CommandId::Unknown(_) => "command (unknown)",
        _ => "command",
    };
    frame_labels(bytes, command, data)
}

pub(super) fn reply_labels(bytes: &[u8], to: CommandId) -> Vec<String> {
    let decoded = if bytes.len() >= 3 { ResponseFrame::decode(&sealed(bytes), to).ok() } else { None };
    let warning = bytes.get(1).is_some_and(|c| c & 0x80 != 0);
    let error = matches!(decoded, Some(ResponseFrame { response: Response::Error(_), .. }));
    let command = match (error, warning) {
        (true, true) => "error response + warning bit",
        (true, false) => "error response",
        (false, true) => "command + warning bit",
        (false, false) => "command",
    };
    frame_labels(bytes, command, decoded.map(|f| response_fields(&f.response)))
}

pub(super) const PRESET: &str = "preset, MSB first";

/// The names of a request's data bytes, in the order the model writes them.
pub(super) fn request_fields(r: &Request) -> Vec<&'static str> {
    use Request::*;
    match r {
        ReadPosition | ReadCounter | IncrementCounter | MemoryStatus | ReadEncoderStatus | ReadTypeLabel
        | EncoderReset | ReadVersion | ReadSyncOffset => vec![],
        SetPosition { .. } | SetPositionInternalSync { .. } | SetPositionWithSync { .. } => {
            vec![PRESET, PRESET, PRESET, PRESET, "Code0"]
        }
        ReadAnalogValue { .. } => vec!["channel"],
        ResetCounter { .. } => vec!["Code0"],
        ReadData { .. } => vec!["field", "offset", "count", "access code"],
        StoreData { data, .. } => {
            let mut v = vec!["field", "offset", "count", "access code"];
            v.extend(std::iter::repeat_n("data", data.len()));
            v
        }
        DataFieldStatus { .. } => vec!["field"],
        CreateDataField { .. } => vec!["field", "status", "access code"],
        SetAccessCode { .. } => vec!["code number", "old code", "new code"],
        SetEncoderAddress { .. } => vec!["new address", "Code0"],
        SetSerialInterface { .. } => vec!["settings", "Code0"],
        TemporarilySetSerialInterface { .. } => vec!["settings"],
        SensorAdjustment { .. } => vec!["option", "Code0"],
    }
}

/// The names of a reply's data bytes, in the order the model writes them; an error
/// code with its name.
pub(super) fn response_fields(r: &Response) -> Vec<String> {
    use Response::*;
    const POSITION: &str = "position, MSB first";
    let names: Vec<&str> = match r {
        PositionSet | CounterIncremented | CounterReset | AddressSet | PositionInternalSyncSet => vec![],
        Position(_) => vec![POSITION; 4],
        PositionWithSyncSet(_) => vec!["preset used, MSB first"; 4],
        AnalogValue { .. } => vec!["channel", "value, MSB first", "value, MSB first"],
        Counter(_) => vec!["counter, MSB first"; 3],
        Data { data, .. } => {
            let mut v = vec!["field", "offset", "count"];
            v.extend(std::iter::repeat_n("data", data.len()));
            v
        }
        DataStored { .. } => vec!["field", "offset", "count"],
        FieldStatus { .. } | FieldCreated { .. } => vec!["field", "status"],
        MemoryStatus { .. } => vec!["free 16-byte blocks", "data fields"],
        AccessCodeSet { .. } => vec!["code number"],
        EncoderStatus(code) | Error(code) => return vec![format!("error code: {}", code.name())],
        TypeLabel { .. } => vec!["settings", "encoder type", "memory, 16-byte blocks", "option"],
        Version(_) => {
            let mut v = vec!["serial number"; 9];
            v.extend(["firmware version"; 20]);
            v.extend(["firmware date"; 8]);
            v
        }
        SerialInterfaceSet { .. } | SerialInterfaceTemporarilySet { .. } => vec!["settings"],
        SensorAdjusted { .. } => vec!["option", "status"],
        SyncOffset(_) => vec!["sync offset"],
    };
    names.into_iter().map(str::to_string).collect()
}
