//! Integer coding.
//!
//! See <https://github.com/PixarAnimationStudios/OpenUSD/blob/0b18ad3f840c24eb25e16b795a5b0821cf05126e/pxr/usd/usd/integerCoding.cpp#L40>

use std::{collections::HashMap, mem};

use num_traits::{AsPrimitive, PrimInt};

use super::ReadError;
use super::reader::Stream;

const COMMON: u8 = 0;
const SMALL: u8 = 1;
const MEDIUM: u8 = 2;
const LARGE: u8 = 3;

pub fn encoded_buffer_size<T: PrimInt>(count: usize) -> usize {
    if count == 0 {
        0
    } else {
        let sz = mem::size_of::<T>();
        // Saturating: a count from a damaged file must not overflow here.
        sz.saturating_add(count.saturating_mul(2).div_ceil(8))
            .saturating_add(sz.saturating_mul(count))
    }
}

// One arm per (code, width) pair of the crate integer encoding, matching the
// layout the writer emits. Merging the arms that happen to read the same
// width would break that row-per-case correspondence.
#[allow(clippy::match_same_arms)]
pub fn decode_ints<T: PrimInt + 'static>(data: &[u8], count: usize) -> Result<Vec<T>, ReadError>
where
    i64: AsPrimitive<T>,
{
    if count == 0 {
        return Ok(Vec::new());
    }

    let is_64_bit = mem::size_of::<T>() == 8;

    let mut codes_reader = Stream::new(data);

    let common_value = if is_64_bit {
        codes_reader.read_pod::<i64>()?
    } else {
        codes_reader.read_pod::<i32>()? as i64
    };

    let num_code_bytes = count
        .checked_mul(2)
        .ok_or_else(|| ReadError::corrupt(format!("integer count {count} overflows")))?
        .div_ceil(8);

    let mut ints_reader = Stream::new(data);
    ints_reader.seek((mem::size_of::<T>() + num_code_bytes) as u64)?;

    let mut prev = 0_i64;
    // Every integer takes at least two bits of `data`.
    let mut output = Vec::with_capacity(count.min(data.len().saturating_mul(4)));

    for _ in 0..num_code_bytes {
        // Code byte stores integer types for the next 4 integers.
        let code_byte = codes_reader.read_pod::<u8>()?;

        for i in 0..4 {
            let ty = (code_byte >> (2 * i)) & 3;
            let delta = match (ty, is_64_bit) {
                (COMMON, _) => common_value,
                (SMALL, true) => ints_reader.read_pod::<i16>()? as i64,
                (SMALL, false) => ints_reader.read_pod::<i8>()? as i64,
                (MEDIUM, true) => ints_reader.read_pod::<i32>()? as i64,
                (MEDIUM, false) => ints_reader.read_pod::<i16>()? as i64,
                (LARGE, true) => ints_reader.read_pod::<i64>()?,
                (LARGE, false) => ints_reader.read_pod::<i32>()? as i64,
                _ => return Err(ReadError::corrupt(format!("Unexpected code: {ty}"))),
            };

            prev = prev.wrapping_add(delta);
            output.push(prev.as_());
        }
    }

    output.truncate(count);
    Ok(output)
}

/// subd: arrays at least this long are coded in two halves on two threads. The halves
/// split at a multiple of four values, so that each half's code bytes are whole; the
/// second half's first delta is taken from the last value of the first. The bytes are
/// those of one pass.
const PARALLEL_MIN: usize = 1 << 18;

/// Encode a sequence of integers using the crate file delta/common-value
/// coding scheme. Inverse of [`decode_ints`].
///
/// Format:
/// 1. Common value (i32 for 32-bit T, i64 for 64-bit T)
/// 2. Code bytes: 2 bits per integer, packed 4 per byte, little-endian
/// 3. Payload: variable-width deltas (COMMON omits, SMALL/MEDIUM/LARGE vary by bit-width)
pub fn encode_ints<T>(values: &[T]) -> Vec<u8>
where
    T: PrimInt + 'static + AsPrimitive<i64> + Sync,
{
    let count = values.len();
    if count == 0 {
        return Vec::new();
    }

    let is_64_bit = mem::size_of::<T>() == 8;
    let split = if count >= PARALLEL_MIN { (count / 2) & !3 } else { count };
    let (first, second) = values.split_at(split);
    let before_second: i64 = if split > 0 { values[split - 1].as_() } else { 0 };

    // Pick the most frequent delta as the common value.
    let parallel = !second.is_empty();
    let (mut counts, second_counts) = join(
        parallel,
        || DeltaCounts::of(deltas(first, 0)),
        || DeltaCounts::of(deltas(second, before_second)),
    );
    counts.merge(second_counts);
    let common = counts.most_common();

    // Assemble output: the common value, the code table, then the payload.
    let header = if is_64_bit { 8 } else { 4 };
    let ((codes, payload), (second_codes, second_payload)) = join(
        parallel,
        || code_deltas(first.len(), deltas(first, 0), common, is_64_bit),
        || code_deltas(second.len(), deltas(second, before_second), common, is_64_bit),
    );
    let size = header + codes.len() + second_codes.len() + payload.len() + second_payload.len();
    let mut out = Vec::with_capacity(size);
    if is_64_bit {
        out.extend_from_slice(&common.to_le_bytes());
    } else {
        out.extend_from_slice(&(common as i32).to_le_bytes());
    }
    for part in [&codes, &second_codes, &payload, &second_payload] {
        out.extend_from_slice(part);
    }
    out
}

/// `a()` and `b()`, `b` on a second thread when `parallel`.
fn join<R: Send>(
    parallel: bool,
    a: impl FnOnce() -> R,
    b: impl FnOnce() -> R + Send,
) -> (R, R) {
    if !parallel {
        return (a(), b());
    }
    std::thread::scope(|s| {
        let other = s.spawn(b);
        let mine = a();
        (mine, other.join().expect("integer coding does not panic"))
    })
}

/// The deltas of `values`, the first taken from `before`: made again for each pass rather
/// than held (subd: two arrays of millions of entries were most of the allocation of a
/// mesh's crate file).
fn deltas<T>(values: &[T], before: i64) -> impl Iterator<Item = i64> + '_
where
    T: PrimInt + 'static + AsPrimitive<i64>,
{
    values.iter().scan(before, |prev, v| {
        let cur: i64 = (*v).as_();
        let d = cur.wrapping_sub(*prev);
        *prev = cur;
        Some(d)
    })
}

/// The code bytes (two bits per delta, four deltas a byte) and the payload of `deltas`.
// One arm per (code, width) pair of the crate integer encoding, matching the
// layout the reader expects. Merging the arms that happen to emit the same
// width would break that row-per-case correspondence.
#[allow(clippy::match_same_arms)]
fn code_deltas(
    count: usize,
    mut deltas: impl Iterator<Item = i64>,
    common: i64,
    is_64_bit: bool,
) -> (Vec<u8>, Vec<u8>) {
    let code_of = |d: i64| {
        if d == common {
            COMMON
        } else if is_64_bit {
            if fits_in_i16(d) {
                SMALL
            } else if fits_in_i32(d) {
                MEDIUM
            } else {
                LARGE
            }
        } else if fits_in_i8(d) {
            SMALL
        } else if fits_in_i16(d) {
            MEDIUM
        } else {
            LARGE
        }
    };
    let mut codes = Vec::with_capacity(count.div_ceil(4));
    let mut payload = Vec::new();
    // Four deltas make one code byte, written once.
    for _ in 0..count.div_ceil(4) {
        let mut byte = 0_u8;
        for (slot, delta) in deltas.by_ref().take(4).enumerate() {
            let code = code_of(delta);
            byte |= code << (2 * slot);
            match (code, is_64_bit) {
                (COMMON, _) => {}
                (SMALL, true) => payload.extend_from_slice(&(delta as i16).to_le_bytes()),
                (SMALL, false) => payload.extend_from_slice(&(delta as i8).to_le_bytes()),
                (MEDIUM, true) => payload.extend_from_slice(&(delta as i32).to_le_bytes()),
                (MEDIUM, false) => payload.extend_from_slice(&(delta as i16).to_le_bytes()),
                (LARGE, true) => payload.extend_from_slice(&delta.to_le_bytes()),
                (LARGE, false) => payload.extend_from_slice(&(delta as i32).to_le_bytes()),
                _ => unreachable!(),
            }
        }
        codes.push(byte);
    }
    (codes, payload)
}

/// How often each delta occurs. Deltas of index arrays are mostly small: those are counted
/// in a table, only the others in a map (subd: hashing every one of millions of deltas was
/// most of the time a mesh's crate file took to write). The answer is the one counting all
/// of them in the map gives.
struct DeltaCounts {
    dense: Vec<usize>,
    sparse: HashMap<i64, usize>,
}

impl DeltaCounts {
    const SPAN: i64 = 1 << 12;

    fn of(deltas: impl Iterator<Item = i64>) -> Self {
        let mut dense = vec![0_usize; 2 * Self::SPAN as usize];
        let mut sparse: HashMap<i64, usize> = HashMap::new();
        for d in deltas {
            if (-Self::SPAN..Self::SPAN).contains(&d) {
                dense[(d + Self::SPAN) as usize] += 1;
            } else {
                *sparse.entry(d).or_insert(0) += 1;
            }
        }
        DeltaCounts { dense, sparse }
    }

    fn merge(&mut self, other: DeltaCounts) {
        for (mine, theirs) in self.dense.iter_mut().zip(other.dense) {
            *mine += theirs;
        }
        for (d, c) in other.sparse {
            *self.sparse.entry(d).or_insert(0) += c;
        }
    }

    fn most_common(self) -> i64 {
        let small = self
            .dense
            .iter()
            .enumerate()
            .filter(|&(_, &c)| c > 0)
            .map(|(i, &c)| (i as i64 - Self::SPAN, c));
        // Tie-break by smallest value so the output is byte-deterministic across
        // runs regardless of `HashMap` iteration order.
        let mut best: Option<(i64, usize)> = None;
        for (value, count) in small.chain(self.sparse) {
            match best {
                None => best = Some((value, count)),
                Some((bv, bc)) if count > bc || (count == bc && value < bv) => {
                    best = Some((value, count));
                }
                _ => {}
            }
        }
        best.map_or(0, |(v, _)| v)
    }
}

fn fits_in_i8(v: i64) -> bool {
    i8::try_from(v).is_ok()
}
fn fits_in_i16(v: i64) -> bool {
    i16::try_from(v).is_ok()
}
fn fits_in_i32(v: i64) -> bool {
    i32::try_from(v).is_ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roundtrip_empty() {
        let out = encode_ints::<i32>(&[]);
        assert!(out.is_empty());
    }

    #[test]
    fn roundtrip_u32() {
        let values: &[u32] = &[123, 124, 125, 100125, 100125, 100126, 100126];
        let encoded = encode_ints(values);
        let decoded = decode_ints::<u32>(&encoded, values.len()).unwrap();
        assert_eq!(decoded, values);
    }

    #[test]
    fn roundtrip_i32_with_negative_deltas() {
        let values: &[i32] = &[10, 5, 3, 100, 99, 200, -50];
        let encoded = encode_ints(values);
        let decoded = decode_ints::<i32>(&encoded, values.len()).unwrap();
        assert_eq!(decoded, values);
    }

    #[test]
    fn roundtrip_u64_large_values() {
        let values: &[u64] = &[0, 1_000_000_000, 5_000_000_000, 9_000_000_000_000];
        let encoded = encode_ints(values);
        let decoded = decode_ints::<u64>(&encoded, values.len()).unwrap();
        assert_eq!(decoded, values);
    }

    #[test]
    fn roundtrip_i64_negative() {
        let values: &[i64] = &[-1_000_000, -999_999, 0, 1_000_000_000_000];
        let encoded = encode_ints(values);
        let decoded = decode_ints::<i64>(&encoded, values.len()).unwrap();
        assert_eq!(decoded, values);
    }

    #[test]
    fn most_common_tie_break_is_deterministic() {
        // Two deltas tied at frequency 2: smallest wins so the encoded output
        // is byte-identical across runs regardless of HashMap iteration order.
        // Values crafted so deltas are [2, 2, 2, 5, 5, 5] — 2 wins on size.
        let values: &[i32] = &[0, 2, 4, 6, 11, 16, 21];
        let a = encode_ints(values);
        let b = encode_ints(values);
        assert_eq!(a, b, "encode_ints output must be byte-deterministic");
        // Sanity: round-trip still works.
        let decoded = decode_ints::<i32>(&a, values.len()).unwrap();
        assert_eq!(decoded, values);
    }

    #[test]
    fn roundtrip_i64_spans_full_range() {
        // Deltas between extreme i64 values overflow signed addition. The
        // decoder must use wrapping arithmetic to mirror the encoder's
        // `wrapping_sub`. Prior to the fix this panicked in debug builds.
        let values: &[i64] = &[i64::MIN, i64::MAX, 0, i64::MIN, i64::MAX];
        let encoded = encode_ints(values);
        let decoded = decode_ints::<i64>(&encoded, values.len()).unwrap();
        assert_eq!(decoded, values);
    }

    #[test]
    fn roundtrip_fieldset_sentinel() {
        // Fieldsets store `None` terminators as `u32::MAX`. Verify that value
        // survives encode_ints/decode_ints round-trip unchanged, including
        // when it appears next to small indices that would otherwise push it
        // into a different integer-coding bucket.
        let values: &[u32] = &[0, 1, 2, u32::MAX, 3, 4, u32::MAX, u32::MAX];
        let encoded = encode_ints(values);
        let decoded = decode_ints::<u32>(&encoded, values.len()).unwrap();
        assert_eq!(decoded, values);
    }

    #[test]
    fn roundtrip_u32_common_delta_exceeds_i32_max() {
        // Deltas exceeding i32 range (here, ±3_000_000_000) still round-trip
        // for 32-bit T: the common slot is stored as i32 and LARGE payloads
        // are written with `as i32`, but the final `prev as T` cast reduces
        // mod 2^32, preserving the correct low bits end-to-end.
        let values: &[u32] = &[0, 3_000_000_000, 0, 3_000_000_000, 0, 3_000_000_000];
        let encoded = encode_ints(values);
        let decoded = decode_ints::<u32>(&encoded, values.len()).unwrap();
        assert_eq!(decoded, values);
    }

    #[test]
    fn test_decode() {
        /*
        See https://github.com/PixarAnimationStudios/OpenUSD/blob/0b18ad3f840c24eb25e16b795a5b0821cf05126e/pxr/usd/usd/integerCoding.cpp#L85
        input  = [123, 124, 125, 100125, 100125, 100126, 100126]
        output = [int32(1) 01 00 00 11 01 00 01 XX int8(123) int32(100000) int8(0) int8(0)]
        */

        let mut output = Vec::new();
        output.extend_from_slice(&1_i32.to_le_bytes());
        debug_assert_eq!(output.len(), 4);

        // Little endian, swap bytes.
        let codes: u16 = 0b1100_0001_0001_0001;
        output.extend_from_slice(&codes.to_be_bytes());
        debug_assert_eq!(output.len(), 6);

        output.extend_from_slice(&123_i8.to_le_bytes());
        output.extend_from_slice(&100000_i32.to_le_bytes());
        output.extend_from_slice(&0_i16.to_le_bytes());

        let input = decode_ints::<u32>(&output, 7).expect("Failed to decode integers");

        assert_eq!(input.as_slice(), &[123_u32, 124, 125, 100125, 100125, 100126, 100126]);
    }
}
