//! The mistakes of one imagined program ([`FaultSet`]): which faults, with their family values,
//! written and read as `no-shadows+gamma-applied=srgb`.

use super::catalogue::{OUTPUT_FAULTS, mask};
use super::*;

/// The mistakes of one imagined program: a set of faults with the values of those that come as a
/// family. Written `no-shadows+gamma-applied=srgb` (catalogue order, `+` between faults); the
/// empty set is `none`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaultSet {
    bits: u64,
    gamma: Gamma,
    length: Length,
    mapping: Mapping,
    flip: Flip,
    bounces: u32,
    background: [u8; 3],
}

impl Default for FaultSet {
    fn default() -> FaultSet {
        FaultSet::NONE
    }
}

impl FaultSet {
    pub const NONE: FaultSet = FaultSet {
        bits: 0,
        gamma: Gamma::Srgb,
        length: Length::Factor(2.0),
        mapping: Mapping::Centres,
        flip: Flip::Vertical,
        bounces: 0,
        background: [0; 3],
    };

    /// One fault, a family's with its first member (`gamma-applied=srgb`,
    /// `specular-unnormalized-reflection=2`, `pixel-mapping=centres`, `cubemap-face-flipped=vertical`,
    /// `wrong-bounces=0`).
    pub fn single(fault: Fault) -> FaultSet {
        FaultSet::NONE.and(fault)
    }

    /// This set and `fault` (a family's with the value it has in this set).
    pub fn and(self, fault: Fault) -> FaultSet {
        FaultSet {
            bits: self.bits | fault.bit(),
            ..self
        }
    }

    /// This set and the family member `parameter` names.
    pub fn with(mut self, parameter: Parameter) -> FaultSet {
        let fault = match parameter {
            Parameter::Gamma(gamma) => {
                self.gamma = gamma;
                Fault::GammaApplied
            }
            Parameter::Length(length) => {
                self.length = length;
                Fault::SpecularUnnormalizedReflection
            }
            Parameter::Mapping(mapping) => {
                self.mapping = mapping;
                Fault::PixelMapping
            }
            Parameter::Flip(flip) => {
                self.flip = flip;
                Fault::CubemapFaceFlipped
            }
            Parameter::Bounces(bounces) => {
                self.bounces = bounces;
                Fault::WrongBounces
            }
            Parameter::Background(color) => {
                self.background = color;
                Fault::CubemapIgnored
            }
        };
        self.and(fault)
    }

    /// The set of `bits` with this set's values where they still apply and the defaults
    /// elsewhere, so that equal sets compare equal however they were made.
    fn keeping(&self, bits: u64) -> FaultSet {
        let has = |fault: Fault| bits & fault.bit() != 0;
        let none = FaultSet::NONE;
        FaultSet {
            bits,
            gamma: if has(Fault::GammaApplied) {
                self.gamma
            } else {
                none.gamma
            },
            length: if has(Fault::SpecularUnnormalizedReflection) {
                self.length
            } else {
                none.length
            },
            mapping: if has(Fault::PixelMapping) {
                self.mapping
            } else {
                none.mapping
            },
            flip: if has(Fault::CubemapFaceFlipped) {
                self.flip
            } else {
                none.flip
            },
            bounces: if has(Fault::WrongBounces) {
                self.bounces
            } else {
                none.bounces
            },
            background: if has(Fault::CubemapIgnored) {
                self.background
            } else {
                none.background
            },
        }
    }

    /// Both sets' faults; `other`'s values win where both have a family.
    pub fn union(self, other: FaultSet) -> FaultSet {
        let mut union = self.keeping(self.bits | other.bits);
        for parameter in other.parameters() {
            union = union.with(parameter);
        }
        union
    }

    /// The family members of this set, as parameters.
    pub fn parameters(&self) -> Vec<Parameter> {
        self.faults()
            .filter_map(|fault| match fault {
                Fault::GammaApplied => Some(Parameter::Gamma(self.gamma)),
                Fault::SpecularUnnormalizedReflection => Some(Parameter::Length(self.length)),
                Fault::PixelMapping => Some(Parameter::Mapping(self.mapping)),
                Fault::CubemapFaceFlipped => Some(Parameter::Flip(self.flip)),
                Fault::WrongBounces => Some(Parameter::Bounces(self.bounces)),
                Fault::CubemapIgnored => Some(Parameter::Background(self.background)),
                _ => None,
            })
            .collect()
    }

    pub fn contains(&self, fault: Fault) -> bool {
        self.bits & fault.bit() != 0
    }

    pub fn is_empty(&self) -> bool {
        self.bits == 0
    }

    pub fn len(&self) -> usize {
        self.bits.count_ones() as usize
    }

    /// The faults, in catalogue order.
    pub fn faults(&self) -> impl Iterator<Item = Fault> + '_ {
        Fault::ALL.into_iter().filter(|f| self.contains(*f))
    }

    pub fn gamma(&self) -> Gamma {
        self.gamma
    }

    pub fn length(&self) -> Length {
        self.length
    }

    pub fn mapping(&self) -> Option<Mapping> {
        self.contains(Fault::PixelMapping).then_some(self.mapping)
    }

    pub fn flip(&self) -> Flip {
        self.flip
    }

    /// The colour of `cubemap-ignored=rrggbb`, linear.
    pub fn background(&self) -> [f64; 3] {
        self.background.map(|c| f64::from(c) / 255.0)
    }

    /// `n` of `wrong-bounces=n`, when the set has it.
    pub fn bounces(&self) -> Option<u32> {
        self.contains(Fault::WrongBounces).then_some(self.bounces)
    }

    /// Whether `fault` of this set acts on the PNGs: the output faults, and `pixel-mapping`'s
    /// flips.
    fn on_output(&self, fault: Fault) -> bool {
        match fault {
            Fault::PixelMapping => self.mapping != Mapping::Centres,
            _ => fault.injection() == Injection::Output,
        }
    }

    /// Without the faults that act on the PNGs: what has to be rendered.
    pub fn render_part(&self) -> FaultSet {
        let bits = self
            .faults()
            .filter(|f| !self.on_output(*f))
            .fold(0, |bits, f| bits | f.bit());
        self.keeping(bits)
    }

    /// Only the faults that act on the PNGs.
    pub fn output_part(&self) -> FaultSet {
        let bits = self
            .faults()
            .filter(|f| self.on_output(*f))
            .fold(0, |bits, f| bits | f.bit());
        self.keeping(bits)
    }

    /// Only the faults acting where `injection` says (`pixel-mapping` as [`Fault::injection`]).
    pub fn only(&self, injection: Injection) -> FaultSet {
        self.keeping(self.bits & mask(injection))
    }

    /// Without `fault`.
    pub fn without(&self, fault: Fault) -> FaultSet {
        self.keeping(self.bits & !fault.bit())
    }

    /// Whether the integrator has anything to check.
    pub fn checks_integrator(&self) -> bool {
        self.bits & INTEGRATOR_FAULTS != 0
    }

    /// Whether the set has faults that act on the PNGs.
    pub fn has_output_faults(&self) -> bool {
        self.bits & OUTPUT_FAULTS != 0 || self.mapping().is_some_and(|m| m != Mapping::Centres)
    }

    /// The pictures any of the faults can change.
    pub fn pictures(&self) -> Pictures {
        self.faults().fold(Pictures::default(), |p, f| p.or(f.pictures()))
    }

    /// One fault's id with its value: `gamma-applied=2.2`, `wrong-bounces=3`, `no-shadows`.
    pub fn label(&self, fault: Fault) -> String {
        let value = match fault {
            Fault::GammaApplied => match self.gamma {
                Gamma::Srgb => "srgb".to_owned(),
                Gamma::Power(g) => short(g),
            },
            Fault::SpecularUnnormalizedReflection => match self.length {
                Length::Factor(k) => short(k),
                Length::HitDistance => "t".to_owned(),
            },
            Fault::PixelMapping => match self.mapping {
                Mapping::Centres => "centres",
                Mapping::UpsideDown => "upside-down",
                Mapping::Mirrored => "mirrored",
            }
            .to_owned(),
            Fault::CubemapFaceFlipped => match self.flip {
                Flip::Vertical => "vertical",
                Flip::Horizontal => "horizontal",
            }
            .to_owned(),
            Fault::WrongBounces => self.bounces.to_string(),
            Fault::CubemapIgnored => self.background.iter().map(|c| format!("{c:02x}")).collect(),
            _ => return fault.name().to_owned(),
        };
        format!("{}={value}", fault.name())
    }

    /// The catalogue ids of the faults, without values, joined by `+`: `no-shadows+gamma-applied`.
    pub fn id(&self) -> String {
        let ids: Vec<&str> = self.faults().map(Fault::name).collect();
        if ids.is_empty() {
            "none".to_owned()
        } else {
            ids.join("+")
        }
    }

    /// What the program does, fault by fault, for the student, with the family member named.
    pub fn explain(&self) -> String {
        let parts: Vec<String> = self
            .faults()
            .map(|fault| match fault {
                Fault::GammaApplied => match self.gamma {
                    Gamma::Srgb => {
                        "the sRGB curve is applied before writing; the course writes linear values".to_owned()
                    }
                    Gamma::Power(g) => {
                        format!(
                            "a gamma of {} is applied before writing; the course writes linear values",
                            short(g)
                        )
                    }
                },
                Fault::SpecularUnnormalizedReflection => {
                    let length = match self.length {
                        Length::Factor(k) => format!("about {} long", short(k)),
                        Length::HitDistance => "as long as the hit distance".to_owned(),
                    };
                    format!(
                        "your specular highlight uses R·V with R not normalised ({length}): highlights come out the \
                             wrong size and brightness"
                    )
                }
                Fault::PixelMapping => match self.mapping {
                    Mapping::Centres => "pixel centres are placed at (x + ½)/w instead of the course's x/(w − 1)",
                    Mapping::UpsideDown => "the picture is upside down: its rows are not flipped when saving",
                    Mapping::Mirrored => "the picture is mirrored left to right (horizontal = up × direction)",
                }
                .to_owned(),
                Fault::CubemapFaceFlipped => match self.flip {
                    Flip::Vertical => "cube-map faces are read upside down (texel rows reversed)",
                    Flip::Horizontal => "cube-map faces are read mirrored (texel columns reversed)",
                }
                .to_owned(),
                Fault::WrongBounces => format!(
                    "the recursion stops after {} bounce{}, not after the number -bounces asks for",
                    self.bounces,
                    if self.bounces == 1 { "" } else { "s" }
                ),
                Fault::CubemapIgnored => {
                    let [r, g, b] = self.background.map(|c| short(f64::from(c) / 255.0));
                    format!("the cube map is ignored: rays that miss see the colour ({r}, {g}, {b})")
                }
                _ => fault.explanation().to_owned(),
            })
            .collect();
        if parts.is_empty() {
            "no mistake".to_owned()
        } else {
            parts.join("; and ")
        }
    }
}

/// A number as short as it reads: `2.2`, `1.85`, `3`.
fn short(value: f64) -> String {
    let text = format!("{value:.2}");
    text.trim_end_matches('0').trim_end_matches('.').to_owned()
}

impl fmt::Display for FaultSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_empty() {
            return f.write_str("none");
        }
        let labels: Vec<String> = self.faults().map(|fault| self.label(fault)).collect();
        f.write_str(&labels.join("+"))
    }
}

impl Serialize for FaultSet {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

/// Why a fault set could not be read.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FaultSetError {
    #[error(transparent)]
    Unknown(#[from] UnknownName),
    #[error("`{0}` takes no value")]
    TakesNoValue(Fault),
    #[error("`{text}` is not a member of {fault}: {expected}")]
    BadValue {
        fault: Fault,
        text: String,
        expected: &'static str,
    },
}

impl FromStr for FaultSet {
    type Err = FaultSetError;

    /// `none`, or faults joined by `+` (or `,`), each `id` or `id=value`.
    fn from_str(text: &str) -> Result<FaultSet, FaultSetError> {
        let mut set = FaultSet::NONE;
        if text.trim() == "none" {
            return Ok(set);
        }
        for part in text.split(['+', ',']).map(str::trim) {
            let (name, value) = match part.split_once('=') {
                Some((name, value)) => (name.trim(), Some(value.trim())),
                None => (part, None),
            };
            let fault: Fault = name.parse()?;
            let Some(value) = value else {
                set = set.and(fault);
                continue;
            };
            let bad = |expected| FaultSetError::BadValue {
                fault,
                text: value.to_owned(),
                expected,
            };
            let number = value
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v > 0.0 && *v <= 100.0);
            let parameter = match fault {
                Fault::GammaApplied => match (value, number) {
                    ("srgb", _) => Parameter::Gamma(Gamma::Srgb),
                    (_, Some(g)) => Parameter::Gamma(Gamma::Power(g)),
                    _ => return Err(bad("srgb, or a positive number")),
                },
                Fault::SpecularUnnormalizedReflection => match (value, number) {
                    ("t", _) => Parameter::Length(Length::HitDistance),
                    (_, Some(k)) => Parameter::Length(Length::Factor(k)),
                    _ => return Err(bad("t, or a positive number")),
                },
                Fault::PixelMapping => Parameter::Mapping(match value {
                    "centres" | "centers" => Mapping::Centres,
                    "upside-down" => Mapping::UpsideDown,
                    "mirrored" => Mapping::Mirrored,
                    _ => return Err(bad("centres, upside-down or mirrored")),
                }),
                Fault::CubemapFaceFlipped => Parameter::Flip(match value {
                    "vertical" => Flip::Vertical,
                    "horizontal" => Flip::Horizontal,
                    _ => return Err(bad("vertical or horizontal")),
                }),
                Fault::WrongBounces => match value.parse::<u32>() {
                    Ok(n) if n <= 1024 => Parameter::Bounces(n),
                    _ => return Err(bad("a whole number from 0 to 1024")),
                },
                Fault::CubemapIgnored => match u32::from_str_radix(value, 16) {
                    Ok(rgb) if value.len() == 6 => {
                        Parameter::Background([(rgb >> 16) as u8, (rgb >> 8) as u8, rgb as u8])
                    }
                    _ => return Err(bad("a colour as six hex digits, rrggbb")),
                },
                _ => return Err(FaultSetError::TakesNoValue(fault)),
            };
            set = set.with(parameter);
        }
        Ok(set)
    }
}
