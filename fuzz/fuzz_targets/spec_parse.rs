//! Spec parsing under arbitrary bytes: TOML and JSON text must give a spec or a typed error,
//! never a panic; an accepted spec must survive its own JSON and TOML round trips unchanged and
//! build its model (or say why not) without panicking.
//!
//! With `--features libfuzzer` (what `cargo fuzz run spec_parse` uses) this is a libFuzzer
//! target. Without it, it is a plain binary that mutates the seed corpus (`fuzz/corpus/
//! spec_parse`, else the examples) with a small deterministic mutator for `--seconds N`, and
//! saves any input that panics under `fuzz/artifacts/spec_parse/`.
#![cfg_attr(feature = "libfuzzer", no_main)]

/// The property under test; panics (the fuzzer's signal) when it does not hold.
fn check(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    for parsed in [
        paritysim_spec::from_toml(text),
        paritysim_spec::from_json(text),
    ] {
        let Ok((spec, _notes)) = parsed else {
            // A typed error: it must name something.
            if let Err(e) = parsed {
                assert!(!e.to_string().is_empty());
            }
            continue;
        };
        let json = spec.to_json();
        let (again, _) = paritysim_spec::from_json(&json)
            .unwrap_or_else(|e| panic!("an accepted spec does not re-read its JSON: {e}\n{json}"));
        assert_eq!(again, spec, "JSON round trip changed the spec");
        let toml = spec.to_toml();
        let (again, _) = paritysim_spec::from_toml(&toml)
            .unwrap_or_else(|e| panic!("an accepted spec does not re-read its TOML: {e}\n{toml}"));
        assert_eq!(again, spec, "TOML round trip changed the spec");
        // Building the model may fail (typed) but never panic.
        let _ = spec.model();
    }
}

#[cfg(feature = "libfuzzer")]
libfuzzer_sys::fuzz_target!(|data: &[u8]| check(data));

#[cfg(not(feature = "libfuzzer"))]
fn main() {
    standalone::main(check);
}

#[cfg(not(feature = "libfuzzer"))]
mod standalone {
    use std::panic::{AssertUnwindSafe, catch_unwind};
    use std::path::{Path, PathBuf};
    use std::time::{Duration, Instant};

    /// Tokens spliced into inputs: TOML/JSON syntax and the values that broke things before.
    const TOKENS: &[&str] = &[
        "=",
        "\"",
        "'",
        "[",
        "]",
        "[[",
        "]]",
        "{",
        "}",
        ",",
        ".",
        "\n",
        "#",
        "-",
        "nan",
        "inf",
        "-inf",
        "1e300",
        "-1e300",
        "5e-324",
        "0",
        "-0.0",
        "1e15",
        "18446744073709551616",
        "9223372036854775808",
        "true",
        "null",
        "\"x\"",
        "[]",
        "{}",
        "options",
        "wings",
        "actuator",
        "drivetrain",
        "frequency_hz",
        "samples_per_cycle",
        "record_cycles",
        "max_wall_ms",
        "segments",
        "kind",
        "\u{feff}",
        "\u{0}",
    ];

    /// xorshift64*: deterministic, no dependency.
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
        }
        fn below(&mut self, n: usize) -> usize {
            (self.next() % n.max(1) as u64) as usize
        }
    }

    fn mutate(rng: &mut Rng, seed: &[u8], corpus: &[Vec<u8>]) -> Vec<u8> {
        let mut data = seed.to_vec();
        for _ in 0..=rng.below(4) {
            let at = rng.below(data.len() + 1);
            match rng.below(6) {
                0 if !data.is_empty() => {
                    let i = at.min(data.len() - 1);
                    data[i] ^= 1 << rng.below(8);
                }
                1 if !data.is_empty() => {
                    let end = (at + rng.below(16)).min(data.len());
                    data.drain(at..end);
                }
                2 | 3 => {
                    let token = TOKENS[rng.below(TOKENS.len())].as_bytes();
                    data.splice(at..at, token.iter().copied());
                }
                4 => {
                    // Replace a number-looking run by a token.
                    let start = at.min(data.len());
                    let end = data[start..]
                        .iter()
                        .position(|b| !(b.is_ascii_digit() || b"+-.eE".contains(b)))
                        .map_or(data.len(), |k| start + k);
                    let token = TOKENS[rng.below(TOKENS.len())].as_bytes();
                    data.splice(start..end, token.iter().copied());
                }
                _ => {
                    // Splice a piece of another seed.
                    let other = &corpus[rng.below(corpus.len())];
                    let from = rng.below(other.len());
                    let to = (from + rng.below(64)).min(other.len());
                    data.splice(at..at, other[from..to].iter().copied());
                }
            }
        }
        data
    }

    fn seeds(root: &Path) -> Vec<Vec<u8>> {
        let mut out = Vec::new();
        for dir in [root.join("fuzz/corpus/spec_parse"), root.join("examples")] {
            let Ok(entries) = std::fs::read_dir(&dir) else {
                continue;
            };
            let mut files: Vec<PathBuf> = entries.flatten().map(|e| e.path()).collect();
            files.sort();
            for f in files {
                let is_seed = dir.ends_with("spec_parse")
                    || f.extension().is_some_and(|e| e == "toml" || e == "json");
                if let (true, Ok(bytes)) = (is_seed, std::fs::read(&f)) {
                    out.push(bytes);
                }
            }
        }
        // The JSON form of every TOML seed too.
        let json: Vec<Vec<u8>> = out
            .iter()
            .filter_map(|b| std::str::from_utf8(b).ok())
            .filter_map(|t| paritysim_spec::from_toml(t).ok())
            .map(|(s, _)| s.to_json().into_bytes())
            .collect();
        out.extend(json);
        if out.is_empty() {
            out.push(b"name = \"x\"\n".to_vec());
        }
        out
    }

    pub fn main(check: fn(&[u8])) {
        let args: Vec<String> = std::env::args().collect();
        let value = |flag: &str, default: u64| {
            args.iter()
                .position(|a| a == flag)
                .and_then(|i| args.get(i + 1))
                .and_then(|v| v.parse().ok())
                .unwrap_or(default)
        };
        let seconds = value("--seconds", 60);
        let mut rng = Rng(value("--seed", 0x5eed) | 1);
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let corpus = seeds(&root);
        let deadline = Instant::now() + Duration::from_secs(seconds);
        std::panic::set_hook(Box::new(|_| {}));
        let (mut runs, mut accepted_utf8) = (0u64, 0u64);
        while Instant::now() < deadline {
            let seed = &corpus[rng.below(corpus.len())];
            let input = mutate(&mut rng, seed, &corpus);
            accepted_utf8 += u64::from(std::str::from_utf8(&input).is_ok());
            runs += 1;
            if catch_unwind(AssertUnwindSafe(|| check(&input))).is_err() {
                let dir = root.join("fuzz/artifacts/spec_parse");
                let _ = std::fs::create_dir_all(&dir);
                let file = dir.join(format!("crash-{runs}"));
                let _ = std::fs::write(&file, &input);
                let _ = std::panic::take_hook();
                check(&input); // re-run with the default hook to print the panic
                eprintln!("panic; input saved to {}", file.display());
                std::process::exit(1);
            }
        }
        println!(
            "spec_parse: {runs} inputs in {seconds} s ({accepted_utf8} valid UTF-8), 0 panics \
             ({} seeds)",
            corpus.len()
        );
    }
}
