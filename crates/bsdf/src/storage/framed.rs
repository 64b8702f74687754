//! The framed binary container of facette's own files (`.fctab` IL body tables,
//! `.fctpart` table parts, `.fcpart` render parts): a frame that says what the file is,
//! which version of its format, how long its contents are, and whether they arrived
//! intact; each format defines only its payload.
//!
//! | bytes | content |
//! |---|---|
//! | 8 | magic: the kind of file (e.g. `FCTBODY1`) |
//! | 4 | u32 format version of that kind |
//! | 8 | u64 payload length P |
//! | P | payload |
//! | 4 | u32 CRC-32 (IEEE) of all preceding bytes |
//!
//! All integers little-endian. The version before each kind adopted the frame had the same
//! layout without the length field (magic, version, payload, CRC of all preceding bytes),
//! so such files are still read, as [`Framed::legacy_version`] allows.

/// One kind of framed file.
#[derive(Clone, Copy, Debug)]
pub struct Framed {
    pub magic: &'static [u8; 8],
    /// The version written.
    pub version: u32,
    /// The version before framing, whose files (no length field, same payload) are still
    /// read; older versions are refused as written by an older facette.
    pub legacy_version: Option<u32>,
    /// What the file is, for messages ("facette IL body table").
    pub what: &'static str,
}

/// What is wrong with a framed file; the caller adds which file.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum FrameError {
    #[error("not a {what} (bad magic number{})", found_kind(.found))]
    WrongKind { what: &'static str, found: Vec<u8> },
    #[error("truncated: {0}")]
    Truncated(String),
    #[error("written by an older facette (format version {found}, this facette reads {current}); regenerate it")]
    Older { found: u32, current: u32 },
    #[error("written by a newer facette (format version {found}, this facette reads up to {current}); update facette to read it")]
    Newer { found: u32, current: u32 },
    #[error("checksum mismatch: the file is corrupt or truncated")]
    Checksum,
}

/// Names the kind of another facette file (all magics start with `FC`) for the message.
fn found_kind(found: &[u8]) -> String {
    match std::str::from_utf8(found) {
        Ok(s) if s.starts_with("FC") && s.chars().all(|c| c.is_ascii_alphanumeric()) => {
            format!("; it is another facette file, of kind `{s}`")
        }
        _ => String::new(),
    }
}

/// A payload read back and the version it was written with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Unframed<'a> {
    pub version: u32,
    pub payload: &'a [u8],
}

const MAGIC: usize = 8;
const HEAD: usize = MAGIC + 4 + 8;
const CRC: usize = 4;

impl Framed {
    /// `payload` in a frame of the current version.
    pub fn frame(&self, payload: &[u8]) -> Vec<u8> {
        let mut out = Vec::with_capacity(HEAD + payload.len() + CRC);
        out.extend_from_slice(self.magic);
        out.extend_from_slice(&self.version.to_le_bytes());
        out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
        out.extend_from_slice(payload);
        let crc = crc32fast::hash(&out);
        out.extend_from_slice(&crc.to_le_bytes());
        out
    }

    /// The payload of `bytes`, checked: kind, version, length, checksum.
    pub fn unframe<'a>(&self, bytes: &'a [u8]) -> Result<Unframed<'a>, FrameError> {
        if bytes.len() < MAGIC || &bytes[..MAGIC] != self.magic {
            return Err(FrameError::WrongKind {
                what: self.what,
                found: bytes[..bytes.len().min(MAGIC)].to_vec(),
            });
        }
        let Some(version) = bytes.get(MAGIC..MAGIC + 4) else {
            return Err(FrameError::Truncated(
                "the file ends inside its header".into(),
            ));
        };
        let version = u32::from_le_bytes(version.try_into().expect("4 bytes"));
        let legacy = Some(version) == self.legacy_version;
        if version > self.version {
            return Err(FrameError::Newer {
                found: version,
                current: self.version,
            });
        }
        if version != self.version && !legacy {
            return Err(FrameError::Older {
                found: version,
                current: self.version,
            });
        }
        let start = if legacy { MAGIC + 4 } else { HEAD };
        if bytes.len() < start + CRC {
            return Err(FrameError::Truncated(
                "the file ends inside its header".into(),
            ));
        }
        let end = bytes.len() - CRC;
        if !legacy {
            let announced = u64::from_le_bytes(bytes[MAGIC + 4..HEAD].try_into().expect("8 bytes"));
            let held = (end - start) as u64;
            if announced != held {
                return Err(FrameError::Truncated(format!(
                    "the header announces {announced} bytes of contents, the file holds {held}{}",
                    if announced > held {
                        ""
                    } else {
                        " (or the file is corrupt)"
                    }
                )));
            }
        }
        let stored = u32::from_le_bytes(bytes[end..].try_into().expect("4 bytes"));
        if crc32fast::hash(&bytes[..end]) != stored {
            return Err(FrameError::Checksum);
        }
        Ok(Unframed {
            version,
            payload: &bytes[start..end],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const KIND: Framed = Framed {
        magic: b"FCTEST01",
        version: 3,
        legacy_version: Some(2),
        what: "facette test file",
    };

    #[test]
    fn round_trip() {
        let bytes = KIND.frame(b"hello");
        assert_eq!(bytes.len(), 20 + 5 + 4);
        let u = KIND.unframe(&bytes).unwrap();
        assert_eq!((u.version, u.payload), (3, &b"hello"[..]));
        assert_eq!(KIND.unframe(&KIND.frame(b"")).unwrap().payload, b"");
    }

    #[test]
    fn the_previous_unframed_version_is_read() {
        let mut bytes = b"FCTEST01".to_vec();
        bytes.extend_from_slice(&2u32.to_le_bytes());
        bytes.extend_from_slice(b"old payload");
        let crc = crc32fast::hash(&bytes);
        bytes.extend_from_slice(&crc.to_le_bytes());
        let u = KIND.unframe(&bytes).unwrap();
        assert_eq!((u.version, u.payload), (2, &b"old payload"[..]));
    }

    #[test]
    fn each_defect_has_its_message() {
        let good = KIND.frame(b"some contents");
        let msg = |b: &[u8]| KIND.unframe(b).unwrap_err().to_string();
        // Wrong kind, naming another facette kind when it is one.
        assert_eq!(
            msg(b"plain text, not ours"),
            "not a facette test file (bad magic number)"
        );
        let other = Framed {
            magic: b"FCRPART1",
            ..KIND
        }
        .frame(b"x");
        assert!(
            msg(&other).contains("another facette file, of kind `FCRPART1`"),
            "{}",
            msg(&other)
        );
        assert!(msg(b"FC").contains("bad magic"));
        // Truncated anywhere.
        for n in [9, 15, 22, good.len() - 1] {
            assert!(
                msg(&good[..n]).starts_with("truncated"),
                "{n}: {}",
                msg(&good[..n])
            );
        }
        // A flipped byte.
        let mut bad = good.clone();
        bad[22] ^= 1;
        assert_eq!(KIND.unframe(&bad).unwrap_err(), FrameError::Checksum);
        // Versions.
        let version = |v: u32| {
            let mut b = good.clone();
            b[8..12].copy_from_slice(&v.to_le_bytes());
            msg(&b)
        };
        assert!(version(1).contains("older facette") && version(1).contains("regenerate"));
        assert!(version(4).contains("newer facette"));
        // Trailing bytes.
        let mut long = good.clone();
        long.push(0);
        assert!(msg(&long).contains("corrupt"));
    }
}
