//! Fuzz target: a URDF file with command-line options through everything a user reaches
//! (`restpose_fuzz::exercise`: import, check, solve, verify on the start and the solved pose);
//! never a panic, never a non-finite number in a result.
//!
//! Input: URDF text (a seed of `seeds` as it is: default options), or two option bytes
//! (the first not `<`) followed by the text. The custom mutator applies the structure-aware
//! mutations of `restpose_fuzz::Mutation` (dictionary `urdf.dict`) and flips the option bytes;
//! one time in four it leaves the bytes to libFuzzer's own mutator.
#![no_main]

use libfuzzer_sys::{fuzz_mutator, fuzz_target, fuzzer_mutate};
use restpose_fuzz::{apply, exercise, Choices, Dictionary, Mutation};
use std::sync::OnceLock;

/// The option bytes and the text of an input.
fn split(data: &[u8]) -> ([u8; 2], &[u8]) {
    match data {
        [a, b, rest @ ..] if *a != b'<' => ([*a, *b], rest),
        _ => ([0, 0], data),
    }
}

fuzz_target!(|data: &[u8]| {
    let ([a, b], text) = split(data);
    exercise(&String::from_utf8_lossy(text), &Choices::from_byte(a, b));
});

/// A small generator for the mutator's choices (xorshift64*).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> usize {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 1) as usize
    }
}

fuzz_mutator!(|data: &mut [u8], size: usize, max_size: usize, seed: u32| {
    let mut rng = Rng(u64::from(seed) | 1 << 40);
    if rng.next() % 4 == 0 {
        return fuzzer_mutate(data, size, max_size);
    }
    static DICTIONARY: OnceLock<Dictionary> = OnceLock::new();
    let d = DICTIONARY.get_or_init(Dictionary::load);
    let ([mut a, mut b], text) = split(&data[..size]);
    let text = String::from_utf8_lossy(text).into_owned();
    let (x, y, z) = (rng.next(), rng.next(), rng.next());
    let m = match rng.next() % 10 {
        0..=2 => Mutation::Number(x, y, z),
        3 => Mutation::Value(x, y),
        4 => Mutation::Rename(x, y),
        5 => Mutation::Tag(x, y),
        6 => Mutation::Attribute(x, y),
        7 => Mutation::Duplicate(x),
        8 => Mutation::Delete(x),
        _ => Mutation::Snippet(x, y, z),
    };
    let text = apply(d, &text, &m);
    if rng.next() % 3 == 0 {
        a ^= 1 << (rng.next() % 8);
        b ^= 1 << (rng.next() % 8);
    }
    if a == b'<' {
        a ^= 1;
    }
    let mut out = vec![a, b];
    out.extend_from_slice(text.as_bytes());
    let n = out.len().min(max_size);
    data[..n].copy_from_slice(&out[..n]);
    n
});
