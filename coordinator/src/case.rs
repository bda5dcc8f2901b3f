//! A case's identity ([`CaseKey`]) and how it ended ([`Status`]): the one
//! definition used by the config, the plan, the journal, the outputs and
//! `solve`. Owns no files, no IPC and no physics.
//!
//! The key's `Display` text (`Cu/flat/015.0`, `Cu/flat/015.0@steel` in a
//! sweep over balls) is for people (progress lines, logs, `fields/<case>/`,
//! the journal's `case_id`); nothing parses it back.

use std::fmt;

use serde::ser::{SerializeStruct, Serializer};

use crate::float_text::fmt_f64;
use serde::{Deserialize, Serialize};

/// Which case of a sweep: material × surface × force angle, by the names
/// the config uses, the ball of a sweep over balls (`sweep.indenters`), and
/// the grid level of a convergence ladder (0: the config's grid; level k has
/// about 2^(k/2) times its points per side on the same domain).
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct CaseKey {
    /// Material name (a preset or a `[materials.*]` key).
    pub material: String,
    /// Surface name (a preset or a `[surfaces.*]` key).
    pub surface: String,
    /// Force direction, degrees.
    pub angle_deg: f64,
    /// Convergence-ladder level. Always serialised: the IPC header's
    /// bincode is not self-describing, so a field that is sometimes left
    /// out cannot be read back; journals written before ladders read as 0.
    #[serde(default)]
    pub level: usize,
    /// The ball of a sweep over balls: an entry of `sweep.indenters`
    /// (`rigid` included). `None` in a sweep without that axis, whose one
    /// ball (`indenter.material`, or rigid) is not part of any identity, so
    /// that its ids, paths, journal lines and CSVs are those of before.
    /// Serialised always in binary formats (the IPC header's bincode), left
    /// out of JSON when `None` (journal lines as before); journals written
    /// before balls read as `None`.
    #[serde(default)]
    pub indenter: Option<String>,
    /// The normal load of a sweep over loads (`sweep.normal_loads_n`), N.
    /// `None` without that axis; serialised like `indenter`.
    #[serde(default)]
    pub normal_n: Option<f64>,
    /// The displacement amplitude of a fretting map (`sweep.amplitudes_um`),
    /// µm. `None` without that axis; serialised like `indenter`.
    #[serde(default)]
    pub amplitude_um: Option<f64>,
}

impl Serialize for CaseKey {
    /// Every field, in order, for bincode (not self-describing: a field
    /// left out could not be read back); in a human-readable format (the
    /// journal's JSON) the axes `indenter`, `normal_n` and `amplitude_um`
    /// only when there is one, so a key without them writes the line it
    /// wrote before those axes existed.
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let readable = s.is_human_readable();
        let ball = !(readable && self.indenter.is_none());
        let load = !(readable && self.normal_n.is_none());
        let amp = !(readable && self.amplitude_um.is_none());
        let n = 4 + [ball, load, amp].iter().filter(|&&b| b).count();
        let mut st = s.serialize_struct("CaseKey", n)?;
        st.serialize_field("material", &self.material)?;
        st.serialize_field("surface", &self.surface)?;
        st.serialize_field("angle_deg", &self.angle_deg)?;
        st.serialize_field("level", &self.level)?;
        if ball {
            st.serialize_field("indenter", &self.indenter)?;
        } else {
            st.skip_field("indenter")?;
        }
        if load {
            st.serialize_field("normal_n", &self.normal_n)?;
        } else {
            st.skip_field("normal_n")?;
        }
        if amp {
            st.serialize_field("amplitude_um", &self.amplitude_um)?;
        } else {
            st.skip_field("amplitude_um")?;
        }
        st.end()
    }
}

impl CaseKey {
    /// The key of `material` × `surface` × `angle_deg`.
    pub fn new(material: &str, surface: &str, angle_deg: f64) -> Self {
        CaseKey {
            material: material.to_string(),
            surface: surface.to_string(),
            angle_deg,
            level: 0,
            indenter: None,
            normal_n: None,
            amplitude_um: None,
        }
    }

    /// The same case at the normal load `normal_n` (N) of a sweep over loads.
    pub fn with_normal_load(mut self, normal_n: f64) -> Self {
        self.normal_n = Some(normal_n);
        self
    }

    /// The same case at the displacement amplitude `amplitude_um` (µm) of a
    /// fretting map.
    pub fn with_amplitude(mut self, amplitude_um: f64) -> Self {
        self.amplitude_um = Some(amplitude_um);
        self
    }

    /// The fretting-map axes as they appear in ids and paths: `@6000N` for
    /// a normal load, `@1.5um` for an amplitude: the numbers as in every
    /// CSV ([`fmt_f64`]: the shortest digits that read back to the same
    /// number, in exponent form outside [1e-3, 1e7), so distinct values give
    /// distinct ids and `1e-250` is not spelt out in 264 characters, #59);
    /// empty without those axes.
    pub fn axes_text(&self) -> String {
        let mut t = String::new();
        if let Some(p) = self.normal_n {
            t.push_str(&format!("@{}N", fmt_f64(p)));
        }
        if let Some(a) = self.amplitude_um {
            t.push_str(&format!("@{}um", fmt_f64(a)));
        }
        t
    }

    /// The same case pressed by the ball `name` of a sweep over balls
    /// (`rigid` for none).
    pub fn with_indenter(mut self, name: &str) -> Self {
        self.indenter = Some(name.to_string());
        self
    }

    /// The same case on ladder level `level`.
    pub fn at_level(mut self, level: usize) -> Self {
        self.level = level;
        self
    }

    /// The key of the curve point this case belongs to (level 0).
    pub fn point(&self) -> CaseKey {
        self.clone().at_level(0)
    }

    /// The angle as it appears in the display text: `015.0`.
    pub fn angle_text(&self) -> String {
        format!("{:05.1}", self.angle_deg)
    }
}

impl fmt::Display for CaseKey {
    /// `material/surface/angle`, e.g. `Cu(111)/circle-A/015.0`, with
    /// `@ball` appended in a sweep over balls (`Cu/flat/000.0@steel`), the
    /// fretting-map axes after it (`Cu/flat/000.0@6000N@1.5um`, see
    /// [`CaseKey::axes_text`]) and `/L2` on ladder level 2 (`Cu/flat/000.0@steel/L2`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}/{}/{}",
            self.material,
            self.surface,
            self.angle_text()
        )?;
        if let Some(ball) = &self.indenter {
            write!(f, "@{ball}")?;
        }
        write!(f, "{}", self.axes_text())?;
        if self.level > 0 {
            write!(f, "/L{}", self.level)?;
        }
        Ok(())
    }
}

/// The exit status of `mpcontact run`, `merge` and `solve` when they wrote
/// their outputs but a case has no `ok` result (failed, or
/// `not_converged`): not 0, so that scripts notice (#59), and not 2, the
/// status of an error that stopped them. (3 is a worker's,
/// `protocol::EXIT_LEFT_WAITING`.)
pub const EXIT_NOT_ALL_OK: u8 = 4;

/// How a recorded case ended. Written as `ok`, `not_converged`, `failed`
/// (results.csv, journal, case.json); journals of older builds that wrote
/// `not-converged` still read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Solved, every loop converged.
    Ok,
    /// Solved, but a loop missed its tolerance; excluded from curves.
    #[serde(alias = "not-converged")]
    NotConverged,
    /// No usable result (solver refusal, invalid result, dead worker).
    Failed,
}

impl Status {
    /// `Ok` when converged, `NotConverged` otherwise.
    pub fn of_solved(converged: bool) -> Self {
        if converged {
            Status::Ok
        } else {
            Status::NotConverged
        }
    }

    /// The text written to files.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::NotConverged => "not_converged",
            Status::Failed => "failed",
        }
    }
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn key_displays_as_the_historic_case_id() {
        assert_eq!(
            CaseKey::new("Cu(111)", "circle-A", 15.0).to_string(),
            "Cu(111)/circle-A/015.0"
        );
        assert_eq!(
            CaseKey::new("Fe", "flat", 180.0).to_string(),
            "Fe/flat/180.0"
        );
        assert_eq!(
            CaseKey::new("Fe", "flat", 180.0).at_level(2).to_string(),
            "Fe/flat/180.0/L2"
        );
    }

    #[test]
    fn keys_without_a_level_read_as_level_zero() {
        let k = CaseKey::new("Cu", "flat", 15.0);
        let old = r#"{"material":"Cu","surface":"flat","angle_deg":15.0}"#;
        let back: CaseKey = serde_json::from_str(old).unwrap();
        assert_eq!(back, k);
        let k2 = k.clone().at_level(1);
        let back: CaseKey = serde_json::from_str(&serde_json::to_string(&k2).unwrap()).unwrap();
        assert_eq!(back, k2);
        assert_eq!(k2.point(), k);
    }

    #[test]
    fn a_ball_shows_in_the_id_and_keys_without_one_write_the_old_json() {
        let k = CaseKey::new("Cu", "flat", 0.0).with_indenter("steel");
        assert_eq!(k.to_string(), "Cu/flat/000.0@steel");
        assert_eq!(k.clone().at_level(1).to_string(), "Cu/flat/000.0@steel/L1");
        assert_eq!(k.clone().at_level(1).point(), k);
        let plain = CaseKey::new("Cu", "flat", 15.0);
        assert_eq!(
            serde_json::to_string(&plain).unwrap(),
            r#"{"material":"Cu","surface":"flat","angle_deg":15.0,"level":0}"#
        );
        let text = serde_json::to_string(&k).unwrap();
        assert!(text.ends_with(r#""level":0,"indenter":"steel"}"#), "{text}");
        assert_eq!(serde_json::from_str::<CaseKey>(&text).unwrap(), k);
        assert_ne!(k, CaseKey::new("Cu", "flat", 0.0).with_indenter("rigid"));
        assert_ne!(k, CaseKey::new("Cu", "flat", 0.0));
    }

    #[test]
    fn issue37_map_axes_show_in_the_id_and_only_then_in_json() {
        let k = CaseKey::new("Cu", "flat", 0.0)
            .with_normal_load(6000.0)
            .with_amplitude(1.5);
        assert_eq!(k.to_string(), "Cu/flat/000.0@6000N@1.5um");
        let a = CaseKey::new("Cu", "flat", 0.0)
            .with_indenter("steel")
            .with_amplitude(0.25);
        assert_eq!(a.to_string(), "Cu/flat/000.0@steel@0.25um");
        let text = serde_json::to_string(&a).unwrap();
        assert!(
            text.ends_with(r#""indenter":"steel","amplitude_um":0.25}"#),
            "{text}"
        );
        assert_eq!(serde_json::from_str::<CaseKey>(&text).unwrap(), a);
        let text = serde_json::to_string(&k).unwrap();
        assert_eq!(serde_json::from_str::<CaseKey>(&text).unwrap(), k);
        for k in [k, a] {
            let env = protocol::Envelope::new("run", (k.clone(), 7u32));
            let bytes = protocol::encode_to_vec(&env, &[]).unwrap();
            let back = protocol::decode::<(CaseKey, u32)>(&bytes, "run").unwrap();
            assert_eq!(back.header.body, (k, 7));
        }
    }

    #[test]
    fn issue59_item6_map_axes_take_the_shortest_text_that_reads_back() {
        // 1e-250 µm was spelt out in 264 characters: a file name too long
        // for the file system, the case's history lost without a word.
        for (v, text) in [
            (1e-250, "1e-250"),
            (1.5, "1.5"),
            (6000.0, "6000"),
            (1e7, "1e7"),
            (1.0 / 3.0, "0.3333333333333333"),
        ] {
            let k = CaseKey::new("Fe", "flat", 0.0).with_amplitude(v);
            assert_eq!(k.axes_text(), format!("@{text}um"));
            assert_eq!(text.parse::<f64>().unwrap().to_bits(), v.to_bits());
        }
        let k = CaseKey::new("Fe", "flat", 0.0).with_normal_load(f64::MIN_POSITIVE);
        assert!(k.to_string().len() < 40, "{k}");
    }

    #[test]
    fn keys_cross_the_wire_with_every_field() {
        // bincode is not self-describing: the key must write `indenter`
        // whether or not it has one, and read back what it wrote.
        for k in [
            CaseKey::new("Cu", "flat", 15.0).at_level(2),
            CaseKey::new("Cu", "flat", 15.0).with_indenter("WC"),
        ] {
            let env = protocol::Envelope::new("run", (k.clone(), 7u32));
            let bytes = protocol::encode_to_vec(&env, &[]).unwrap();
            let back = protocol::decode::<(CaseKey, u32)>(&bytes, "run").unwrap();
            assert_eq!(back.header.body, (k, 7));
        }
    }

    #[test]
    fn key_round_trips_through_json_bit_exactly() {
        let k = CaseKey::new("Cu", "flat", 1.0 / 3.0);
        let back: CaseKey = serde_json::from_str(&serde_json::to_string(&k).unwrap()).unwrap();
        assert_eq!(back.angle_deg.to_bits(), k.angle_deg.to_bits());
        assert_eq!(back, k);
    }

    #[test]
    fn status_text_and_old_spelling() {
        for (s, t) in [
            (Status::Ok, "ok"),
            (Status::NotConverged, "not_converged"),
            (Status::Failed, "failed"),
        ] {
            assert_eq!(s.to_string(), t);
            assert_eq!(serde_json::to_string(&s).unwrap(), format!("\"{t}\""));
            assert_eq!(
                serde_json::from_str::<Status>(&format!("\"{t}\"")).unwrap(),
                s
            );
        }
        assert_eq!(
            serde_json::from_str::<Status>("\"not-converged\"").unwrap(),
            Status::NotConverged
        );
        assert!(serde_json::from_str::<Status>("\"fine\"").is_err());
    }
}
