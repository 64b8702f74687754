//! The binary encoding of a view's numbers: a little-endian `u32` length, a JSON header
//! (`{"arrays": [{"name", "len"}…], …}` plus the view's own fields), zero padding to a
//! multiple of 8 bytes, then each array as little-endian `f64`, in the header's order. The
//! app reads the arrays as `Float64Array`s without copying; `f64` keeps every digit, so the
//! app's numbers are the ones `facette eval` prints.

use serde_json::{json, Map, Value};

/// Named arrays and header fields.
#[derive(Clone, Debug, Default)]
pub struct Frame {
    pub fields: Map<String, Value>,
    pub arrays: Vec<(String, Vec<f64>)>,
}

impl Frame {
    pub fn field(mut self, key: &str, value: impl Into<Value>) -> Self {
        self.fields.insert(key.to_string(), value.into());
        self
    }

    pub fn array(mut self, name: &str, values: Vec<f64>) -> Self {
        self.arrays.push((name.to_string(), values));
        self
    }

    pub fn encode(&self) -> Vec<u8> {
        let mut header = self.fields.clone();
        header.insert(
            "arrays".into(),
            Value::Array(
                self.arrays
                    .iter()
                    .map(|(n, v)| json!({"name": n, "len": v.len()}))
                    .collect(),
            ),
        );
        let head = serde_json::to_vec(&Value::Object(header)).expect("a JSON map serializes");
        let start = (4 + head.len()).div_ceil(8) * 8;
        let total = start + 8 * self.arrays.iter().map(|(_, v)| v.len()).sum::<usize>();
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(&(head.len() as u32).to_le_bytes());
        out.extend_from_slice(&head);
        out.resize(start, 0);
        for (_, v) in &self.arrays {
            for x in v {
                out.extend_from_slice(&x.to_le_bytes());
            }
        }
        out
    }

    /// Reads an encoded frame back (the tests' and any Rust client's side).
    pub fn decode(bytes: &[u8]) -> Option<Frame> {
        let n = u32::from_le_bytes(bytes.get(..4)?.try_into().ok()?) as usize;
        let Value::Object(mut fields) = serde_json::from_slice(bytes.get(4..4 + n)?).ok()? else {
            return None;
        };
        let Some(Value::Array(list)) = fields.remove("arrays") else {
            return None;
        };
        let mut at = (4 + n).div_ceil(8) * 8;
        let mut arrays = Vec::new();
        for a in list {
            let name = a.get("name")?.as_str()?.to_string();
            let len = a.get("len")?.as_u64()? as usize;
            let raw = bytes.get(at..at + 8 * len)?;
            let v = raw
                .chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
                .collect();
            arrays.push((name, v));
            at += 8 * len;
        }
        (at == bytes.len()).then_some(Frame { fields, arrays })
    }

    pub fn get(&self, name: &str) -> Option<&[f64]> {
        self.arrays
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_with_aligned_arrays() {
        let f = Frame::default()
            .field("theta_i", 30.0)
            .array("a", vec![1.0, f64::NAN, -0.5])
            .array("b", vec![]);
        let bytes = f.encode();
        let start = bytes.len() - 8 * 3;
        assert_eq!(start % 8, 0);
        let g = Frame::decode(&bytes).unwrap();
        assert_eq!(g.fields["theta_i"], 30.0);
        assert_eq!(g.get("a").unwrap()[0], 1.0);
        assert!(g.get("a").unwrap()[1].is_nan());
        assert_eq!(g.get("b").unwrap().len(), 0);
        assert!(Frame::decode(&bytes[..bytes.len() - 1]).is_none());
    }
}
