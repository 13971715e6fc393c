//! Small arithmetic expressions in scene files (initial velocity fields), evaluated
//! with evalexpr in the reference position x, y, z.
//!
//! evalexpr parses and evaluates by recursion, so a deeply nested expression
//! (`((((…x))))`, `----…x`) would overflow the stack and abort the program. An
//! expression is therefore held to [`MAX_LENGTH`] characters and [`MAX_DEPTH`]
//! levels of parentheses before it is parsed; initial fields need far less.

use evalexpr::{ContextWithMutableFunctions, ContextWithMutableVariables, DefaultNumericTypes};

type Function = evalexpr::Function<DefaultNumericTypes>;
type HashMapContext = evalexpr::HashMapContext<DefaultNumericTypes>;
type Value = evalexpr::Value<DefaultNumericTypes>;

fn unary(f: fn(f64) -> f64) -> Function {
    Function::new(move |v| Ok(Value::Float(f(v.as_number()?))))
}

/// The longest expression accepted, in characters.
pub const MAX_LENGTH: usize = 1000;
/// The deepest nesting of parentheses accepted.
pub const MAX_DEPTH: usize = 64;

/// An expression within [`MAX_LENGTH`] and [`MAX_DEPTH`], or why not.
pub fn check_size(expr: &str) -> Result<(), String> {
    let length = expr.chars().count();
    if length > MAX_LENGTH {
        return Err(format!(
            "the expression has {length} characters, more than {MAX_LENGTH}"
        ));
    }
    let mut depth = 0usize;
    for c in expr.chars() {
        match c {
            '(' => depth += 1,
            ')' => depth = depth.saturating_sub(1),
            _ => {}
        }
        if depth > MAX_DEPTH {
            return Err(format!(
                "the expression nests parentheses more than {MAX_DEPTH} deep"
            ));
        }
    }
    Ok(())
}

/// Evaluate `expr` at position `x` (x, y, z). Errors are messages for the user.
pub fn eval(expr: &str, x: &[f64; 3]) -> Result<f64, String> {
    check_size(expr)?;
    let mut ctx = HashMapContext::new();
    let set = |ctx: &mut HashMapContext, k: &str, v: f64| ctx.set_value(k.into(), Value::Float(v));
    let ok = set(&mut ctx, "x", x[0])
        .and(set(&mut ctx, "y", x[1]))
        .and(set(&mut ctx, "z", x[2]))
        .and(set(&mut ctx, "pi", std::f64::consts::PI));
    ok.map_err(|e| e.to_string())?;
    for (name, f) in [
        ("sin", f64::sin as fn(f64) -> f64),
        ("cos", f64::cos),
        ("exp", f64::exp),
        ("sqrt", f64::sqrt),
        ("abs", f64::abs),
    ] {
        ctx.set_function(name.into(), unary(f))
            .map_err(|e| e.to_string())?;
    }
    let v = evalexpr::eval_number_with_context(expr, &ctx)
        .map_err(|e| format!("cannot evaluate expression `{expr}`: {e}"))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("expression `{expr}` is not finite at {x:?}"))
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn evaluates_with_position_and_functions() {
        let v = super::eval("0.1*sin(pi*x/50) + y", &[25.0, 2.0, 0.0]).unwrap();
        assert!((v - 2.1).abs() < 1e-14);
        assert!(super::eval("1 + ", &[0.0; 3]).is_err());
        assert!(super::eval("q*2", &[0.0; 3]).is_err());
    }

    #[test]
    fn deep_and_long_expressions_are_refused_before_parsing() {
        let deep = format!("{}x{}", "(".repeat(65), ")".repeat(65));
        let e = super::eval(&deep, &[0.0; 3]).unwrap_err();
        assert!(e.contains("more than 64 deep"), "{e}");
        let ok = format!("{}x{}", "(".repeat(64), ")".repeat(64));
        assert_eq!(super::eval(&ok, &[2.0, 0.0, 0.0]), Ok(2.0));
        // A chain of unary minus nests as deep as its length.
        let long = format!("{}x", "-".repeat(100_000));
        let e = super::eval(&long, &[0.0; 3]).unwrap_err();
        assert!(e.contains("more than 1000"), "{e}");
    }
}
