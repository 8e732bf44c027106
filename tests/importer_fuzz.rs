//! The importer never panics: robot files mutated at random (bytes cut, lines doubled,
//! numbers replaced by garbage, characters inserted) load or fail with an error, and what
//! loads also solves or fails with an error. 64 cases per run here (`PROPTEST_CASES` raises
//! it); the cargo-fuzz target in `fuzz/` does the same coverage-guided.
use proptest::prelude::*;

fn robots() -> Vec<String> {
    let dir = format!("{}/robots", env!("CARGO_MANIFEST_DIR"));
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "urdf"))
        .map(|p| std::fs::read_to_string(p).unwrap())
        .collect();
    v.sort();
    v
}

#[derive(Clone, Debug)]
enum Mutation {
    Cut(usize, usize),
    DoubleLine(usize),
    Number(usize, &'static str),
    Insert(usize, char),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), 1..40usize).prop_map(|(a, n)| Mutation::Cut(a, n)),
        any::<usize>().prop_map(Mutation::DoubleLine),
        (
            any::<usize>(),
            prop::sample::select(vec![
                "nan", "inf", "-1e999", "1e308", "-0", "", "0 0", "x", "-5", "1e-320"
            ])
        )
            .prop_map(|(a, s)| Mutation::Number(a, s)),
        (
            any::<usize>(),
            prop::sample::select(vec!['<', '>', '"', '&', '/', '=', ' ', 'é', '\0', '$'])
        )
            .prop_map(|(a, c)| Mutation::Insert(a, c)),
    ]
}

fn apply(text: &str, m: &Mutation) -> String {
    let chars: Vec<char> = text.chars().collect();
    let n = chars.len().max(1);
    match *m {
        Mutation::Cut(a, len) => {
            let a = a % n;
            let b = (a + len).min(chars.len());
            chars[..a].iter().chain(&chars[b..]).collect()
        }
        Mutation::DoubleLine(a) => {
            let lines: Vec<&str> = text.lines().collect();
            let k = a % lines.len().max(1);
            let mut out: Vec<&str> = lines.clone();
            if let Some(l) = lines.get(k) {
                out.insert(k, l);
            }
            out.join("\n")
        }
        Mutation::Number(a, s) => {
            // Replace the a-th number-like token.
            let positions: Vec<usize> = (0..chars.len())
                .filter(|&i| {
                    chars[i].is_ascii_digit()
                        && (i == 0 || !chars[i - 1].is_ascii_alphanumeric() && chars[i - 1] != '.')
                })
                .collect();
            if positions.is_empty() {
                return text.to_string();
            }
            let start = positions[a % positions.len()];
            let mut end = start;
            while end < chars.len()
                && (chars[end].is_ascii_digit()
                    || chars[end] == '.'
                    || chars[end] == 'e'
                    || chars[end] == '-')
            {
                end += 1;
            }
            chars[..start]
                .iter()
                .copied()
                .chain(s.chars())
                .chain(chars[end..].iter().copied())
                .collect()
        }
        Mutation::Insert(a, c) => {
            let a = a % n;
            chars[..a]
                .iter()
                .copied()
                .chain(std::iter::once(c))
                .chain(chars[a..].iter().copied())
                .collect()
        }
    }
}

fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(64)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    #[test]
    fn mutated_robot_files_never_panic(which in any::<usize>(), muts in prop::collection::vec(mutation(), 1..4)) {
        let all = robots();
        let mut text = all[which % all.len()].clone();
        for m in &muts {
            text = apply(&text, m);
        }
        if let Ok(l) = restpose::urdf::load_str(&text, "mutated.urdf", &Default::default()) {
            let opts = restpose::Options { max_iterations: 20, load_steps: 1, ..Default::default() };
            let _ = restpose::solve(&l.model, &opts);
            let _ = restpose::export::summary::ModelSummary::new(&l, &restpose::verify::check(&l.model));
        }
    }
}

/// Hostile structure: a robot file with a random nesting of `depth` levels (elements,
/// comments, self-closing tags and quoted `>` mixed in) inside a link. It loads when
/// `depth` is within `MAX_DEPTH` and is refused with a located error beyond it: never a
/// stack overflow, whatever the depth.
fn nested(depth: usize, noise: &[u8]) -> String {
    let mut open = String::new();
    for (i, &n) in noise.iter().cycle().take(depth).enumerate() {
        match n % 4 {
            0 => open.push_str("<a>"),
            1 => open.push_str("<b v=\"x>y\"><!-- <c> --><d/>"),
            2 => open.push_str("<e><![CDATA[<f>]]>"),
            _ => open.push_str(&format!("<g{i} w='/>'>")),
        }
    }
    let mut close = String::new();
    for (i, &n) in noise
        .iter()
        .cycle()
        .take(depth)
        .enumerate()
        .collect::<Vec<_>>()
        .into_iter()
        .rev()
    {
        close.push_str(&match n % 4 {
            0 => "</a>".to_string(),
            1 => "</b>".to_string(),
            2 => "</e>".to_string(),
            _ => format!("</g{i}>"),
        });
    }
    format!("<robot name=\"r\"><link name=\"l\"><visual>{open}{close}</visual></link></robot>")
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases().min(32)))]

    #[test]
    fn deep_nesting_is_refused_not_overflowed(depth in 0usize..20_000, noise in prop::collection::vec(any::<u8>(), 1..8)) {
        let text = nested(depth, &noise);
        // robot, link and visual are 3 levels above the nesting.
        let limit = restpose::urdf::MAX_DEPTH;
        match restpose::urdf::load_str(&text, "deep.urdf", &Default::default()) {
            Ok(_) => prop_assert!(depth + 3 <= limit, "depth {depth} accepted"),
            Err(e) => {
                let e = e.to_string();
                prop_assert!(depth + 3 > limit, "depth {depth} refused: {e}");
                prop_assert!(e.starts_with("deep.urdf:1:") && e.contains("nested more than"), "{e}");
            }
        }
    }
}
