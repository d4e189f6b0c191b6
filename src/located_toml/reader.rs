//! The readers: a table with its keys checked, and a value with the key it was found under.

use std::fmt;
use std::ops::{Range, RangeInclusive};

use toml::Spanned;
use toml::de::{DeString, DeTable, DeValue};

use super::{Doc, LocatedError, Result, suggest};
use crate::named_enum::NamedEnum;

type Value<'i> = Spanned<DeValue<'i>>;

/// A TOML table plus the name it goes by in messages ("[render]", "sphere", "point light").
pub(crate) struct Table<'a, 'i> {
    pub doc: &'a Doc<'a>,
    pub what: String,
    pub span: Range<usize>,
    /// Sorted by position, so that the first problem reported is the first one in the file.
    entries: Vec<(&'a Spanned<DeString<'i>>, &'a Value<'i>)>,
}

impl<'a, 'i> Table<'a, 'i> {
    pub fn new(doc: &'a Doc<'a>, what: String, span: Range<usize>, table: &'a DeTable<'i>) -> Self {
        let mut entries: Vec<_> = table.iter().collect();
        entries.sort_by_key(|(key, _)| key.span().start);
        Table {
            doc,
            what,
            span,
            entries,
        }
    }

    /// Stands in for an absent optional section, so that it reads as all defaults.
    pub fn empty(doc: &'a Doc<'a>, what: &str) -> Self {
        Table {
            doc,
            what: what.to_owned(),
            span: 0..0,
            entries: Vec::new(),
        }
    }

    pub fn fields(&self) -> impl Iterator<Item = Field<'a, 'i>> + '_ {
        self.entries.iter().map(|&(key, value)| Field {
            doc: self.doc,
            name: key.get_ref().to_string(),
            key_span: key.span(),
            value,
        })
    }

    pub fn get(&self, name: &str) -> Option<Field<'a, 'i>> {
        self.fields().find(|f| f.name == name)
    }

    pub fn require(&self, name: &str) -> Result<Field<'a, 'i>> {
        self.get(name).ok_or_else(|| {
            self.doc
                .error_at(&self.span, format!("{} is missing required key `{name}`", self.what))
        })
    }

    pub fn check_keys(&self, allowed: &[&str]) -> Result<()> {
        self.check_keys_with(allowed, |_| None)
    }

    /// Rejects the first key not in `allowed`. `owner` names the other kinds a stray key belongs
    /// to, because `offset` on a sphere is a different mistake from a typo and deserves a
    /// different hint.
    pub fn check_keys_with(&self, allowed: &[&str], owner: impl Fn(&str) -> Option<String>) -> Result<()> {
        let Some(field) = self.fields().find(|f| !allowed.contains(&f.name.as_str())) else {
            return Ok(());
        };
        let (name, what) = (&field.name, &self.what);
        let message = match owner(name) {
            Some(kinds) => format!(
                "key `{name}` does not apply to a {what} (it is a {kinds} key); valid keys for a \
                 {what}: {}",
                allowed.join(", ")
            ),
            None => format!("unknown key `{name}` in {what}{}", suggest(name, allowed, "keys")),
        };
        Err(self.doc.error_at(&field.key_span, message))
    }

    /// Reads the required `kind` string of a tagged table (an object or a light), renames the
    /// table after it, and checks the keys against `common` plus that kind's own.
    pub fn kind<K: Copy>(&mut self, noun: &str, common: &[&str], kinds: &[(&str, &[&str], K)]) -> Result<K> {
        let field = self.require("kind")?;
        let written = field.string()?;
        let Some(&(name, own, kind)) = kinds.iter().find(|(k, _, _)| *k == written) else {
            let names: Vec<&str> = kinds.iter().map(|(k, _, _)| *k).collect();
            let tail = suggest(written, &names, "kinds");
            return Err(field.error(format!("unknown {noun} kind `{written}`{tail}")));
        };
        // "in sphere" reads naturally, "in point" does not: only lights keep their noun.
        self.what = if noun == "object" {
            name.to_owned()
        } else {
            format!("{name} {noun}")
        };
        let allowed: Vec<&str> = common.iter().chain(own).copied().collect();
        self.check_keys_with(&allowed, |key| {
            let owners: Vec<&str> = kinds
                .iter()
                .filter(|(_, keys, _)| keys.contains(&key))
                .map(|(k, _, _)| *k)
                .collect();
            (!owners.is_empty()).then(|| owners.join("/"))
        })?;
        Ok(kind)
    }

    /// `read` applied to the key if present, else `default`: how every optional setting is read.
    /// The error type is the reader's, so that a file's own checks can return their own errors.
    pub fn read<T, E>(
        &self,
        name: &str,
        default: T,
        read: impl FnOnce(&Field<'a, 'i>) -> std::result::Result<T, E>,
    ) -> std::result::Result<T, E> {
        self.get(name).map_or(Ok(default), |f| read(&f))
    }
}

/// One value with the key (or `key[index]`) it was found under.
pub(crate) struct Field<'a, 'i> {
    pub doc: &'a Doc<'a>,
    pub name: String,
    pub key_span: Range<usize>,
    value: &'a Value<'i>,
}

impl<'a, 'i> Field<'a, 'i> {
    pub fn span(&self) -> Range<usize> {
        self.value.span()
    }

    pub fn excerpt(&self) -> String {
        self.doc.excerpt(&self.span())
    }

    pub fn error(&self, message: impl Into<String>) -> LocatedError {
        self.doc.error_at(&self.span(), message)
    }

    /// "`requirement`, found `what was written`", the shape of nearly every value error.
    pub fn invalid(&self, requirement: impl fmt::Display) -> LocatedError {
        self.error(format!("{} {requirement}, found {}", self.name, self.excerpt()))
    }

    fn wrong_type(&self, expected: &str) -> LocatedError {
        let found = self.value.get_ref().type_str();
        self.error(format!(
            "{} must be {expected}, found {found} {}",
            self.name,
            self.excerpt()
        ))
    }

    /// Any finite number; TOML integers count, because `fov = 30` is what people write.
    pub fn number(&self) -> Result<f64> {
        let value = match self.value.get_ref() {
            DeValue::Integer(_) => self.integer()? as f64,
            DeValue::Float(f) => f.as_str().parse::<f64>().map_err(|_| self.wrong_type("a number"))?,
            _ => return Err(self.wrong_type("a number")),
        };
        if value.is_finite() {
            Ok(value)
        } else {
            Err(self.invalid("must be a finite number"))
        }
    }

    pub fn integer(&self) -> Result<i64> {
        let DeValue::Integer(i) = self.value.get_ref() else {
            return Err(self.wrong_type("an integer"));
        };
        i64::from_str_radix(i.as_str(), i.radix()).map_err(|_| self.invalid("must be an integer that fits in 64 bits"))
    }

    /// An integer in `range`, converted to the type the renderer stores it in.
    pub fn integer_in<T: TryFrom<i64>>(&self, range: RangeInclusive<i64>, requirement: &str) -> Result<T> {
        let value = self.integer()?;
        match T::try_from(value) {
            Ok(v) if range.contains(&value) => Ok(v),
            _ => Err(self.invalid(requirement)),
        }
    }

    pub fn non_negative(&self) -> Result<f64> {
        let value = self.number()?;
        if value >= 0.0 {
            Ok(value)
        } else {
            Err(self.invalid("must be ≥ 0"))
        }
    }

    pub fn boolean(&self) -> Result<bool> {
        self.value
            .get_ref()
            .as_bool()
            .ok_or_else(|| self.wrong_type("true or false"))
    }

    pub fn string(&self) -> Result<&'a str> {
        self.value.get_ref().as_str().ok_or_else(|| self.wrong_type("a string"))
    }

    pub fn table(&self, what: String) -> Result<Table<'a, 'i>> {
        match self.value.get_ref() {
            DeValue::Table(t) => Ok(Table::new(self.doc, what, self.span(), t)),
            _ => Err(self.wrong_type("a table")),
        }
    }

    /// The elements, each named `name[i]` so that its own errors point inside the array.
    pub fn array(&self, expected: &str) -> Result<Vec<Field<'a, 'i>>> {
        let DeValue::Array(items) = self.value.get_ref() else {
            return Err(self.wrong_type(expected));
        };
        Ok(items
            .iter()
            .enumerate()
            .map(|(i, value)| Field {
                doc: self.doc,
                name: format!("{}[{i}]", self.name),
                key_span: value.span(),
                value,
            })
            .collect())
    }

    pub fn numbers<const N: usize>(&self, expected: &str) -> Result<[f64; N]> {
        let items = self.array(expected)?;
        if items.len() != N {
            let n = items.len();
            return Err(self.invalid(format!("must be {expected}, but has {n} elements")));
        }
        let mut out = [0.0; N];
        for (slot, item) in out.iter_mut().zip(&items) {
            *slot = item.number()?;
        }
        Ok(out)
    }

    /// A string naming a variant of one of the crate's option enums. The valid names come from
    /// the enum's own definition, so they cannot drift from what the renderer accepts.
    pub fn variant<T: NamedEnum>(&self) -> Result<T> {
        let written = self.string()?;
        T::from_name(written).ok_or_else(|| {
            let tail = suggest(written, T::NAMES, "values");
            self.error(format!("unknown {} `{written}`{tail}", self.name))
        })
    }
}
