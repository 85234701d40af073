//! `modelDescription.xml` of the FMU (FMI 2.0, co-simulation only), written from
//! [`super::VARIABLES`] and [`super::UNITS`].
//!
//! Choices, each an attribute of the FMI 2.0 schema:
//! - `canHandleVariableCommunicationStepSize="true"`: each `fmi2DoStep` integrates to `t + h`
//!   with CVODE's own variable steps, whatever `h`;
//! - `canInterpolateInputs="false"`, `maxOutputDerivativeOrder="0"`: inputs are held over a
//!   step (zero-order hold), no output derivatives;
//! - `canGetAndSetFMUstate="false"`, `canSerializeFMUstate="false"`,
//!   `providesDirectionalDerivative="false"`: not implemented (the binary answers `fmi2Error`);
//! - `canBeInstantiatedOnlyOncePerProcess="false"`: every instance owns its CVODE context;
//! - `canNotUseMemoryManagementFunctions="true"`: the binary allocates with Rust's allocator;
//! - `ModelStructure`: every output is listed under `Outputs` and `InitialUnknowns` with
//!   `dependencies=""` — no direct feed-through (outputs are functions of the state; inputs
//!   and parameters enter through the accelerations);
//! - `DefaultExperiment`: the reduced model's span, CVODE's relative tolerance of `jointrom
//!   transient` (1e-8; the binary uses `fmi2SetupExperiment`'s tolerance as rtol when the
//!   importer defines one) and its output step 1e-4 s.

use std::fmt::Write;

use super::{guid, model_identifier, Causality, Variability, UNITS, VARIABLES};
use crate::integrate::TransientOptions;
use crate::rom::file::RomFile;

/// Text with the five XML special characters escaped (for attribute values), control
/// characters other than tab and newline dropped (XML 1.0 cannot carry them).
fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\t' => out.push_str("&#9;"),
            '\n' => out.push_str("&#10;"),
            c if c.is_control() => {}
            c => out.push(c),
        }
    }
    out
}

/// A number as an `xs:double` that reads back to the same `f64` (Rust's shortest round-trip
/// form, e.g. `10000.0`, `0.3`, `1e-8`).
fn number(x: f64) -> String {
    format!("{x:?}")
}

/// The model description of the FMU of `rom`, whose `resources/rom.json` holds `rom_json`
/// (the GUID is computed from those bytes, [`super::guid`]).
pub fn model_description(rom: &RomFile, rom_json: &[u8]) -> String {
    let defaults = TransientOptions::default();
    let mut x = String::new();
    let case = escape(&rom.case);
    // `write!` into a String cannot fail.
    let _ = write!(
        x,
        r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription
  fmiVersion="2.0"
  modelName="jointrom reduced model of {case}"
  guid="{guid}"
  description="{desc}"
  generationTool="jointrom {version}"
  version="{version}"
  variableNamingConvention="flat"
  numberOfEventIndicators="0">
  <CoSimulation
    modelIdentifier="{id}"
    needsExecutionTool="false"
    canHandleVariableCommunicationStepSize="true"
    canInterpolateInputs="false"
    maxOutputDerivativeOrder="0"
    canRunAsynchronuously="false"
    canBeInstantiatedOnlyOncePerProcess="false"
    canNotUseMemoryManagementFunctions="true"
    canGetAndSetFMUstate="false"
    canSerializeFMUstate="false"
    providesDirectionalDerivative="false"/>
  <UnitDefinitions>
"#,
        guid = guid(rom_json),
        desc = escape(&format!(
            "Reduced model of {} ({} basis, g = {}, r = {} coordinates, {} joint pairs) with \
             penalty contact and Coulomb friction, integrated by jointrom (CVODE BDF)",
            rom.case, rom.basis.kind, rom.basis.g, rom.dimension, rom.pairs
        )),
        version = env!("CARGO_PKG_VERSION"),
        id = model_identifier(&rom.case),
    );
    for (name, [kg, m, s, rad], factor) in UNITS {
        let mut base = String::new();
        for (key, e) in [("kg", kg), ("m", m), ("s", s), ("rad", rad)] {
            if e != 0 {
                let _ = write!(base, r#" {key}="{e}""#);
            }
        }
        if factor != 1.0 {
            let _ = write!(base, r#" factor="{}""#, number(factor));
        }
        let _ = writeln!(
            x,
            r#"    <Unit name="{}"><BaseUnit{base}/></Unit>"#,
            escape(name)
        );
    }
    let _ = write!(
        x,
        r#"  </UnitDefinitions>
  <LogCategories>
    <Category name="logStatusError" description="Errors: refused calls and arguments, integrator failures (always logged)"/>
    <Category name="logAll" description="Diagnostics: instantiation, restarts of the integrator after an input change, step statistics"/>
  </LogCategories>
  <DefaultExperiment startTime="0.0" stopTime="{stop}" tolerance="{tol}" stepSize="{step}"/>
  <ModelVariables>
"#,
        stop = number(rom.end_time),
        tol = number(defaults.ode.rtol),
        step = number(defaults.output_step),
    );
    for (i, v) in VARIABLES.iter().enumerate() {
        let causality = match v.causality {
            Causality::Input => "input",
            Causality::Output => "output",
            Causality::Parameter => "parameter",
        };
        let variability = match v.variability {
            Variability::Fixed => "fixed",
            Variability::Tunable => "tunable",
            Variability::Continuous => "continuous",
        };
        let mut real = String::new();
        if let Some(u) = v.unit {
            let _ = write!(real, r#" unit="{}""#, escape(u));
        }
        if let Some(s) = v.start_value(rom) {
            let _ = write!(real, r#" start="{}""#, number(s));
        }
        let _ = write!(
            x,
            r#"    <!-- index {index} -->
    <ScalarVariable name="{name}" valueReference="{vr}" description="{desc}" causality="{causality}" variability="{variability}">
      <Real{real}/>
    </ScalarVariable>
"#,
            index = i + 1,
            name = escape(v.name),
            vr = v.vr,
            desc = escape(v.description),
        );
    }
    let outputs: String = VARIABLES
        .iter()
        .enumerate()
        .filter(|(_, v)| v.causality == Causality::Output)
        .map(|(i, _)| format!("      <Unknown index=\"{}\" dependencies=\"\"/>\n", i + 1))
        .collect();
    let _ = write!(
        x,
        r#"  </ModelVariables>
  <ModelStructure>
    <Outputs>
{outputs}    </Outputs>
    <InitialUnknowns>
{outputs}    </InitialUnknowns>
  </ModelStructure>
</fmiModelDescription>
"#
    );
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escape_handles_markup_quotes_and_controls() {
        assert_eq!(
            escape("a<b & \"c\" 'd'>\u{1b}e\n"),
            "a&lt;b &amp; &quot;c&quot; &apos;d&apos;&gt;e&#10;"
        );
    }

    #[test]
    fn numbers_round_trip() {
        for x in [0.0, 1.0, 0.3, 1e-8, 1e4, 123456.789, 2.5e-300] {
            assert_eq!(number(x).parse::<f64>().unwrap(), x);
        }
    }
}
