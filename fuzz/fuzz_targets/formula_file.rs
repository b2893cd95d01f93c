//! Formula files (`kiln verify-fit FILE`): the text is parsed as a formula file; a file that
//! parses is evaluated over the domain's corners and middle (a NaN is the formula's, not a
//! fault), and a refusal's message may hold no raw control character (issue 64: messages quote
//! a file's text escaped and bounded).
#![no_main]

use kiln::fit::{Fit, FormulaFit};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match FormulaFit::parse(text) {
        Ok(fit) => {
            let fit = Fit::Formula(fit);
            for quantity in fit.quantities() {
                for (mu, r) in [(0.0, 0.0), (0.5, 0.5), (1.0, 1.0), (1e-9, 1e-9)] {
                    let _ = fit.value(quantity, mu, r);
                }
            }
        }
        Err(error) => {
            let message = error.to_string();
            assert!(!message.chars().any(|c| c.is_control() && c != '\n'));
        }
    }
});
