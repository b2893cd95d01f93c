//! Spellings of the last release that name a command of this one: kept working for one release,
//! with a note on stderr that names the new spelling.

use std::ffi::OsString;

/// A mode flag of an older command that is now a command of its own.
struct Renamed {
    /// The command the flag belonged to.
    command: &'static str,
    flag: &'static str,
    /// Whether the flag took a value, which is now the new command's first argument.
    takes_value: bool,
    /// The command that replaces the flag.
    new: &'static str,
}

/// The renamed modes (2026-12: `kiln verify`'s modes that took other inputs, and `kiln plan`'s
/// scene, now its argument as `kiln verify`'s table is).
const RENAMED: [Renamed; 4] = [
    Renamed {
        command: "verify",
        flag: "--furnace",
        takes_value: false,
        new: "furnace",
    },
    Renamed {
        command: "verify",
        flag: "--fit",
        takes_value: true,
        new: "verify-fit",
    },
    Renamed {
        command: "verify",
        flag: "--anisotropy-convention",
        takes_value: true,
        new: "verify-anisotropy",
    },
    Renamed {
        command: "plan",
        flag: "--scene",
        takes_value: true,
        new: "plan",
    },
];

/// The command line with an old spelling rewritten to the new command (`kiln verify --furnace
/// FILE` -> `kiln furnace FILE`, `kiln verify --fit karis` -> `kiln verify-fit karis`), and the
/// note that says so; the command line unchanged and no note otherwise.
pub fn rewrite(args: Vec<OsString>) -> (Vec<OsString>, Option<String>) {
    let Some(command) = args.get(1).and_then(|a| a.to_str()) else {
        return (args, None);
    };
    for renamed in RENAMED.iter().filter(|r| r.command == command) {
        let with_value = format!("{}=", renamed.flag);
        let Some(at) = args.iter().position(|a| {
            a.to_str()
                .is_some_and(|a| a == renamed.flag || a.starts_with(&with_value))
        }) else {
            continue;
        };
        let mut rest: Vec<OsString> = args[2..].to_vec();
        let flag = rest.remove(at - 2);
        let mut value = None;
        if renamed.takes_value {
            match flag.to_str().and_then(|f| f.strip_prefix(&with_value)) {
                Some(inline) => value = Some(OsString::from(inline)),
                None if at - 2 < rest.len() => value = Some(rest.remove(at - 2)),
                None => {}
            }
        }
        let mut rewritten = vec![args[0].clone(), OsString::from(renamed.new)];
        rewritten.extend(value);
        rewritten.extend(rest);
        let note = format!(
            "note: `kiln {} {}` is now `kiln {}`; the old spelling works in this release only",
            renamed.command, renamed.flag, renamed.new
        );
        return (rewritten, Some(note));
    }
    (args, None)
}

#[cfg(test)]
mod tests {
    use super::rewrite;
    use std::ffi::OsString;

    fn words(line: &str) -> Vec<OsString> {
        line.split(' ').map(OsString::from).collect()
    }

    #[test]
    fn a_mode_flag_becomes_its_command_and_its_value_the_first_argument() {
        let cases = [
            (
                "kiln verify --furnace t/E.json --form turquin",
                "kiln furnace t/E.json --form turquin",
            ),
            ("kiln verify t/E.json --furnace", "kiln furnace t/E.json"),
            (
                "kiln verify --fit karis --json",
                "kiln verify-fit karis --json",
            ),
            (
                "kiln verify --json --fit=f.toml",
                "kiln verify-fit f.toml --json",
            ),
            (
                "kiln verify --anisotropy-convention disney -q",
                "kiln verify-anisotropy disney -q",
            ),
            ("kiln plan --scene s.toml --json", "kiln plan s.toml --json"),
        ];
        for (old, new) in cases {
            let (args, note) = rewrite(words(old));
            assert_eq!(args, words(new), "{old}");
            assert!(note.is_some_and(|n| n.contains("is now `kiln ")), "{old}");
        }
    }

    #[test]
    fn other_command_lines_are_left_alone() {
        for line in [
            "kiln verify t/E.json --json",
            "kiln bake --fit",
            "kiln",
            "kiln furnace x",
        ] {
            let (args, note) = rewrite(words(line));
            assert_eq!(args, words(line));
            assert!(note.is_none());
        }
    }
}
