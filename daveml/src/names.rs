//! The DAVE-ML names sepval writes: one per input of its tables and one per field, each a name
//! the default map ([`crate::map`]) reads back as that input or field.

use sepval_common::correction::Target;
use sepval_common::table::Variable;

/// The DAVE-ML name of an input.
pub fn input_id(v: Variable) -> &'static str {
    v.csv_name()
}

/// The DAVE-ML name of a field (one the default map reads back as that field).
pub fn output_id(t: Target) -> &'static str {
    const STATIC: [&str; 6] = ["CA", "CY", "CZ", "Cl", "Cm", "Cn"];
    const DERIVATIVE: [&str; 7] = [
        "CZalpha", "CYbeta", "Cmalpha", "Cnbeta", "Clp", "Cmq", "Cnr",
    ];
    const INTERFERENCE: [&str; 6] = ["dCX", "dCY", "dCZ", "dCl", "dCm", "dCn"];
    match t {
        Target::Static(k) => STATIC[k],
        Target::Derivative(d) => {
            let k = sepval_common::correction::Derivative::ALL
                .iter()
                .position(|&e| e == d)
                .expect("every derivative is listed");
            DERIVATIVE[k]
        }
        Target::Interference(k) => INTERFERENCE[k],
        Target::Field(_) | Target::ShapeTable => unreachable!(
            "the flowfield is not the store's data: DAVE-ML carries the store's tables (Target::all)"
        ),
    }
}
