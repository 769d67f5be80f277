//! ISO 10303-21 ("Part 21", the clear-text encoding of STEP): a tokenizer over the bytes and
//! the table of the DATA section's entity instances. Every instance is kept as written, a
//! simple entity (`#12 = CARTESIAN_POINT('', (0., 1., 2.));`) or a complex one
//! (`#13 = (BOUNDED_SURFACE() B_SPLINE_SURFACE(...) ...);`, its partial entities in the order
//! written); what the instances mean is the business of the modules above this one.
//!
//! Reading is defensive: nothing is allocated from a count the file declares (lists grow as
//! their items are read, so a list is never larger than the text that holds it), nesting
//! deeper than [`MAX_DEPTH`] and more than [`MAX_ENTITIES`] instances are refused, and every
//! error names the line and, inside the DATA section, the instance (`#123`).

use std::collections::HashMap;
use std::fmt;

/// The deepest nesting of lists and typed parameters.
pub const MAX_DEPTH: usize = 32;
/// The most entity instances in one file.
pub const MAX_ENTITIES: usize = 4_000_000;

/// The smallest file [`Parsing::step_in_parallel`] shares out.
const PARALLEL_PARSE_BYTES: usize = 1 << 16;

/// One parameter of an entity instance.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// `#123`
    Ref(u64),
    Integer(i64),
    Real(f64),
    /// A string with its escapes decoded.
    Str(String),
    /// `.T.`, `.UNSPECIFIED.` (without the dots).
    Enum(String),
    /// `(a, b, c)`
    List(Vec<Value>),
    /// `LENGTH_MEASURE(2.5)`: a typed parameter.
    Typed(String, Box<Value>),
    /// `"0A"`: a binary.
    Binary(String),
    /// `$`: no value.
    Null,
    /// `*`: derived.
    Derived,
}

impl Value {
    /// A short name of the value's type, for messages.
    pub fn type_name(&self) -> &'static str {
        match self {
            Value::Ref(_) => "a reference",
            Value::Integer(_) => "an integer",
            Value::Real(_) => "a real",
            Value::Str(_) => "a string",
            Value::Enum(_) => "an enumeration",
            Value::List(_) => "a list",
            Value::Typed(..) => "a typed value",
            Value::Binary(_) => "a binary",
            Value::Null => "$",
            Value::Derived => "*",
        }
    }
}

/// One simple entity (or one partial entity of a complex instance): its type in capitals and
/// its parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    pub name: String,
    pub args: Vec<Value>,
}

/// An entity instance: simple, or complex (several partial entities).
#[derive(Debug, Clone, PartialEq)]
pub enum Instance {
    Simple(Record),
    Complex(Vec<Record>),
}

impl Instance {
    /// The partial entity named `name` (the instance itself when it is simple and so named).
    pub fn part(&self, name: &str) -> Option<&Record> {
        match self {
            Instance::Simple(r) => (r.name == name).then_some(r),
            Instance::Complex(parts) => parts.iter().find(|r| r.name == name),
        }
    }

    /// The type's name (a complex instance: its partial types joined by `+`).
    pub fn type_name(&self) -> String {
        match self {
            Instance::Simple(r) => r.name.clone(),
            Instance::Complex(parts) => parts
                .iter()
                .map(|r| r.name.as_str())
                .collect::<Vec<_>>()
                .join("+"),
        }
    }

    /// Whether the instance is, or has a partial entity, of type `name`.
    pub fn is(&self, name: &str) -> bool {
        self.part(name).is_some()
    }
}

/// A file that is not (well-formed) Part 21.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntaxError {
    pub line: usize,
    /// The instance being read, if any.
    pub entity: Option<u64>,
    pub message: String,
}

impl fmt::Display for SyntaxError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self.entity {
            Some(id) => write!(f, "line {}, #{id}: {}", self.line, self.message),
            None => write!(f, "line {}: {}", self.line, self.message),
        }
    }
}

/// The file's header and its DATA section's instances.
#[derive(Debug, Default)]
pub struct Exchange {
    /// The header's entities (`FILE_DESCRIPTION`, `FILE_NAME`, `FILE_SCHEMA`).
    pub header: Vec<Record>,
    /// Instances by their number, in the order written.
    pub instances: Vec<(u64, Instance)>,
    index: InstanceIndex,
}

impl Exchange {
    pub fn get(&self, id: u64) -> Option<&Instance> {
        self.index
            .get(id)
            .and_then(|k| self.instances.get(k))
            .map(|(_, instance)| instance)
    }

    /// The schema names of `FILE_SCHEMA`, upper case.
    pub fn schemas(&self) -> Vec<String> {
        let mut out = Vec::new();
        for r in self.header.iter().filter(|r| r.name == "FILE_SCHEMA") {
            if let Some(Value::List(items)) = r.args.first() {
                for item in items {
                    if let Value::Str(s) = item {
                        out.push(s.to_ascii_uppercase());
                    }
                }
            }
        }
        out
    }
}

/// Where each instance number's instance is in [`Exchange::instances`]: a table by number for
/// the numbers files use (below twice the instances read, and 65,536 more: a look-up is one
/// read, where hashing a number cost a tenth of a read's time), and a hash map for the others.
#[derive(Debug, Default)]
struct InstanceIndex {
    /// The place plus one of instance `k` at `dense[k]`; 0 where it has none.
    dense: Vec<u32>,
    sparse: HashMap<u64, usize>,
}

impl InstanceIndex {
    /// The smallest number beyond the table's reach when `count` instances are read.
    fn reach(count: usize) -> usize {
        2 * count + (1 << 16)
    }

    fn get(&self, id: u64) -> Option<usize> {
        let dense = usize::try_from(id)
            .ok()
            .and_then(|k| self.dense.get(k))
            .filter(|&&at| at != 0)
            .map(|&at| at as usize - 1);
        if dense.is_some() || self.sparse.is_empty() {
            return dense;
        }
        self.sparse.get(&id).copied()
    }

    /// Records that instance `id` is at `at`, the `at`-th read; false (nothing recorded) where
    /// `id` has a place already.
    fn insert(&mut self, id: u64, at: usize) -> bool {
        if self.get(id).is_some() {
            return false;
        }
        let k = usize::try_from(id).unwrap_or(usize::MAX);
        let reach = Self::reach(at + 1);
        if k >= self.dense.len() && k < reach {
            let grown = (2 * self.dense.len()).clamp(k + 1, reach);
            self.dense.resize(grown, 0);
        }
        match (self.dense.get_mut(k), u32::try_from(at + 1)) {
            (Some(slot), Ok(place)) => *slot = place,
            _ => {
                self.sparse.insert(id, at);
            }
        }
        true
    }

    /// Room for the table of `count` instances' numbers, set aside at once.
    fn reserve(&mut self, count: usize) {
        self.dense
            .reserve(Self::reach(count).saturating_sub(self.dense.len()));
    }

    fn remove(&mut self, id: u64) {
        match usize::try_from(id).ok().and_then(|k| self.dense.get_mut(k)) {
            Some(slot) if *slot != 0 => *slot = 0,
            _ => {
                self.sparse.remove(&id);
            }
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Token {
    Keyword(String),
    Ref(u64),
    Integer(i64),
    Real(f64),
    Str(String),
    Enum(String),
    Binary(String),
    Open,
    Close,
    Comma,
    Semicolon,
    Equals,
    Dollar,
    Star,
    End,
}

struct Lexer<'a> {
    bytes: &'a [u8],
    at: usize,
    line: usize,
    entity: Option<u64>,
}

impl<'a> Lexer<'a> {
    fn error(&self, message: impl Into<String>) -> SyntaxError {
        SyntaxError {
            line: self.line,
            entity: self.entity,
            message: message.into(),
        }
    }

    fn skip_space(&mut self) -> Result<(), SyntaxError> {
        loop {
            match self.bytes.get(self.at) {
                Some(b'\n') => {
                    self.line += 1;
                    self.at += 1;
                }
                Some(c) if c.is_ascii_whitespace() => self.at += 1,
                Some(b'/') if self.bytes.get(self.at + 1) == Some(&b'*') => {
                    let start = self.line;
                    self.at += 2;
                    loop {
                        match self.bytes.get(self.at) {
                            None => {
                                return Err(SyntaxError {
                                    line: start,
                                    entity: self.entity,
                                    message: "a comment that never ends (/* without */)".into(),
                                });
                            }
                            Some(b'*') if self.bytes.get(self.at + 1) == Some(&b'/') => {
                                self.at += 2;
                                break;
                            }
                            Some(b'\n') => {
                                self.line += 1;
                                self.at += 1;
                            }
                            Some(_) => self.at += 1,
                        }
                    }
                }
                _ => return Ok(()),
            }
        }
    }

    fn next(&mut self) -> Result<Token, SyntaxError> {
        self.skip_space()?;
        let Some(&c) = self.bytes.get(self.at) else {
            return Ok(Token::End);
        };
        let single = match c {
            b'(' => Some(Token::Open),
            b')' => Some(Token::Close),
            b',' => Some(Token::Comma),
            b';' => Some(Token::Semicolon),
            b'=' => Some(Token::Equals),
            b'$' => Some(Token::Dollar),
            b'*' => Some(Token::Star),
            _ => None,
        };
        if let Some(t) = single {
            self.at += 1;
            return Ok(t);
        }
        match c {
            b'#' => {
                self.at += 1;
                let digits = self.take_while(|b| b.is_ascii_digit());
                if digits.is_empty() {
                    return Err(self.error("'#' without an instance number"));
                }
                digits
                    .parse::<u64>()
                    .map(Token::Ref)
                    .map_err(|_| self.error(format!("instance number #{digits} is too large")))
            }
            b'\'' => self.string().map(Token::Str),
            b'"' => {
                self.at += 1;
                let hex = self.take_while(|b| b.is_ascii_hexdigit());
                if self.bytes.get(self.at) != Some(&b'"') {
                    return Err(self.error("a binary value without its closing '\"'"));
                }
                self.at += 1;
                Ok(Token::Binary(hex))
            }
            b'.' => {
                self.at += 1;
                let word = self.take_while(|b| b.is_ascii_alphanumeric() || b == b'_');
                if self.bytes.get(self.at) != Some(&b'.') || word.is_empty() {
                    return Err(self.error("an enumeration without its closing '.'"));
                }
                self.at += 1;
                Ok(Token::Enum(word.to_ascii_uppercase()))
            }
            b'+' | b'-' | b'0'..=b'9' => self.number(),
            b'!' | b'A'..=b'Z' | b'a'..=b'z' | b'_' => {
                let word = self.take_while(|b| {
                    b.is_ascii_alphanumeric() || b == b'_' || b == b'-' || b == b'!'
                });
                Ok(Token::Keyword(word.to_ascii_uppercase()))
            }
            other => Err(self.error(format!("unexpected character {:?}", char::from(other)))),
        }
    }

    fn take_while(&mut self, keep: impl Fn(u8) -> bool) -> String {
        let start = self.at;
        while self.bytes.get(self.at).is_some_and(|&b| keep(b)) {
            self.at += 1;
        }
        String::from_utf8_lossy(&self.bytes[start..self.at]).into_owned()
    }

    fn number(&mut self) -> Result<Token, SyntaxError> {
        let start = self.at;
        if matches!(self.bytes.get(self.at), Some(b'+' | b'-')) {
            self.at += 1;
        }
        let mut real = false;
        while let Some(&b) = self.bytes.get(self.at) {
            match b {
                b'0'..=b'9' => {}
                b'.' => real = true,
                b'E' | b'e' => {
                    real = true;
                    if matches!(self.bytes.get(self.at + 1), Some(b'+' | b'-')) {
                        self.at += 1;
                    }
                }
                _ => break,
            }
            self.at += 1;
        }
        let text = String::from_utf8_lossy(&self.bytes[start..self.at]).into_owned();
        // "1.E-5" and "2." are reals in Part 21; Rust reads both.
        if real {
            let parsed = text
                .parse::<f64>()
                .ok()
                .or_else(|| text.replace(".E", ".0E").replace(".e", ".0e").parse().ok());
            match parsed {
                Some(x) if x.is_finite() => Ok(Token::Real(x)),
                _ => Err(self.error(format!("'{text}' is not a finite number"))),
            }
        } else {
            text.parse::<i64>()
                .map(Token::Integer)
                .or_else(|_| match text.parse::<f64>() {
                    Ok(x) if x.is_finite() => Ok(Token::Real(x)),
                    _ => Err(self.error(format!("'{text}' is not a number"))),
                })
        }
    }

    /// A string: `''` is a quote; `\X2\hhhh…\X0\` and `\X4\…\X0\` are UTF-16 and UTF-32
    /// code points, `\X\hh` an ISO 8859-1 byte, `\\` a backslash; `\S\c` and `\P…\` pass as
    /// written.
    fn string(&mut self) -> Result<String, SyntaxError> {
        let start_line = self.line;
        self.at += 1;
        let mut raw = Vec::new();
        loop {
            match self.bytes.get(self.at) {
                None => {
                    return Err(SyntaxError {
                        line: start_line,
                        entity: self.entity,
                        message: "a string that never ends (the text is truncated?)".into(),
                    });
                }
                Some(b'\'') if self.bytes.get(self.at + 1) == Some(&b'\'') => {
                    raw.push(b'\'');
                    self.at += 2;
                }
                Some(b'\'') => {
                    self.at += 1;
                    break;
                }
                Some(&b) => {
                    if b == b'\n' {
                        self.line += 1;
                    }
                    if b != b'\n' && b != b'\r' {
                        raw.push(b);
                    }
                    self.at += 1;
                }
            }
        }
        Ok(decode_string(&raw))
    }
}

/// Decodes Part 21's string escapes (see [`Lexer::string`]) byte by byte; what cannot be
/// decoded is kept as written.
fn decode_string(raw: &[u8]) -> String {
    if !raw.contains(&b'\\') {
        return String::from_utf8_lossy(raw).into_owned();
    }
    let upper = |k: usize| raw.get(k).map(u8::to_ascii_uppercase);
    let hex = |bytes: &[u8]| -> Option<u32> {
        std::str::from_utf8(bytes)
            .ok()
            .and_then(|h| u32::from_str_radix(h, 16).ok())
    };
    let mut out: Vec<u8> = Vec::with_capacity(raw.len());
    let push = |out: &mut Vec<u8>, c: char| {
        let mut buffer = [0u8; 4];
        out.extend_from_slice(c.encode_utf8(&mut buffer).as_bytes());
    };
    let mut i = 0;
    while i < raw.len() {
        if raw[i] != b'\\' {
            out.push(raw[i]);
            i += 1;
            continue;
        }
        let wide = match (upper(i + 1), upper(i + 2), upper(i + 3)) {
            (Some(b'X'), Some(b'2'), Some(b'\\')) => Some(4),
            (Some(b'X'), Some(b'4'), Some(b'\\')) => Some(8),
            _ => None,
        };
        if let Some(width) = wide {
            let body = i + 4;
            let end = (body..raw.len()).find(|&k| {
                raw[k] == b'\\'
                    && upper(k + 1) == Some(b'X')
                    && upper(k + 2) == Some(b'0')
                    && upper(k + 3) == Some(b'\\')
            });
            if let Some(end) = end {
                let digits = &raw[body..end];
                if digits.len().is_multiple_of(width) && digits.iter().all(u8::is_ascii_hexdigit) {
                    let units: Vec<u32> = digits.chunks(width).filter_map(hex).collect();
                    if width == 4 {
                        let u16s: Vec<u16> = units.iter().map(|&u| u as u16).collect();
                        for c in char::decode_utf16(u16s) {
                            push(&mut out, c.unwrap_or(char::REPLACEMENT_CHARACTER));
                        }
                    } else {
                        for u in units {
                            push(
                                &mut out,
                                char::from_u32(u).unwrap_or(char::REPLACEMENT_CHARACTER),
                            );
                        }
                    }
                    i = end + 4;
                    continue;
                }
            }
        }
        if upper(i + 1) == Some(b'X')
            && upper(i + 2) == Some(b'\\')
            && let Some(c) = raw
                .get(i + 3..i + 5)
                .filter(|h| h.iter().all(u8::is_ascii_hexdigit))
                .and_then(hex)
        {
            push(&mut out, char::from(c as u8));
            i += 5;
            continue;
        }
        if raw.get(i + 1) == Some(&b'\\') {
            out.push(b'\\');
            i += 2;
            continue;
        }
        out.push(b'\\');
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

struct Parser<'a> {
    lexer: Lexer<'a>,
    peeked: Option<Token>,
}

impl<'a> Parser<'a> {
    fn peek(&mut self) -> Result<&Token, SyntaxError> {
        if self.peeked.is_none() {
            self.peeked = Some(self.lexer.next()?);
        }
        Ok(self.peeked.as_ref().unwrap_or(&Token::End))
    }

    fn next(&mut self) -> Result<Token, SyntaxError> {
        match self.peeked.take() {
            Some(t) => Ok(t),
            None => self.lexer.next(),
        }
    }

    fn expect(&mut self, want: Token, what: &str) -> Result<(), SyntaxError> {
        let got = self.next()?;
        if got == want {
            Ok(())
        } else {
            Err(self
                .lexer
                .error(format!("expected {what}, found {}", describe(&got))))
        }
    }

    /// The '(' after `name` ([`Self::expect`] without formatting the message unless needed:
    /// that showed in profiles).
    fn open_after(&mut self, name: &str) -> Result<(), SyntaxError> {
        match self.next()? {
            Token::Open => Ok(()),
            got => Err(self.lexer.error(format!(
                "expected '(' after {name}, found {}",
                describe(&got)
            ))),
        }
    }

    /// `NAME(args)`: the name has been read.
    fn record(&mut self, name: String, depth: usize) -> Result<Record, SyntaxError> {
        self.open_after(&name)?;
        let args = self.list_items(depth + 1)?;
        Ok(Record { name, args })
    }

    /// The items of a list whose '(' has been read, through its ')'.
    fn list_items(&mut self, depth: usize) -> Result<Vec<Value>, SyntaxError> {
        if depth > MAX_DEPTH {
            return Err(self
                .lexer
                .error(format!("lists nested more than {MAX_DEPTH} deep")));
        }
        let mut items = Vec::new();
        if self.peek()? == &Token::Close {
            self.next()?;
            return Ok(items);
        }
        loop {
            items.push(self.value(depth)?);
            match self.next()? {
                Token::Comma => {}
                Token::Close => return Ok(items),
                other => {
                    return Err(self.lexer.error(format!(
                        "expected ',' or ')' in a parameter list, found {}",
                        describe(&other)
                    )));
                }
            }
        }
    }

    fn value(&mut self, depth: usize) -> Result<Value, SyntaxError> {
        Ok(match self.next()? {
            Token::Ref(id) => Value::Ref(id),
            Token::Integer(i) => Value::Integer(i),
            Token::Real(x) => Value::Real(x),
            Token::Str(s) => Value::Str(s),
            Token::Enum(e) => Value::Enum(e),
            Token::Binary(b) => Value::Binary(b),
            Token::Dollar => Value::Null,
            Token::Star => Value::Derived,
            Token::Open => Value::List(self.list_items(depth + 1)?),
            Token::Keyword(name) => {
                self.open_after(&name)?;
                let mut inner = self.list_items(depth + 1)?;
                let value = if inner.len() == 1 {
                    inner.pop().unwrap_or(Value::Null)
                } else {
                    Value::List(inner)
                };
                Value::Typed(name, Box::new(value))
            }
            other => {
                return Err(self
                    .lexer
                    .error(format!("expected a parameter, found {}", describe(&other))));
            }
        })
    }

    /// Records up to `ENDSEC;` (the header's entities).
    fn header(&mut self) -> Result<Vec<Record>, SyntaxError> {
        let mut out = Vec::new();
        loop {
            match self.next()? {
                Token::Keyword(k) if k == "ENDSEC" => {
                    self.expect(Token::Semicolon, "';' after ENDSEC")?;
                    return Ok(out);
                }
                Token::Keyword(name) => {
                    out.push(self.record(name, 0)?);
                    self.expect(Token::Semicolon, "';' after a header entity")?;
                }
                Token::End => {
                    return Err(self.lexer.error("the file ends inside its HEADER section"));
                }
                other => {
                    return Err(self.lexer.error(format!(
                        "expected a header entity, found {}",
                        describe(&other)
                    )));
                }
            }
        }
    }

    /// One `#id = ...;` instance whose `#id` has been read.
    fn instance(&mut self, id: u64) -> Result<Instance, SyntaxError> {
        self.lexer.entity = Some(id);
        self.expect(Token::Equals, "'=' after the instance number")?;
        let instance = match self.next()? {
            Token::Keyword(name) => Instance::Simple(self.record(name, 0)?),
            Token::Open => {
                let mut parts = Vec::new();
                loop {
                    match self.next()? {
                        Token::Keyword(name) => parts.push(self.record(name, 1)?),
                        Token::Close => break,
                        other => {
                            return Err(self.lexer.error(format!(
                                "expected a partial entity in a complex instance, found {}",
                                describe(&other)
                            )));
                        }
                    }
                }
                if parts.is_empty() {
                    return Err(self
                        .lexer
                        .error("a complex instance with no partial entities"));
                }
                Instance::Complex(parts)
            }
            other => {
                return Err(self.lexer.error(format!(
                    "expected an entity type, found {}",
                    describe(&other)
                )));
            }
        };
        self.expect(Token::Semicolon, "';' after the instance")?;
        self.lexer.entity = None;
        Ok(instance)
    }
}

/// The parse of a piece of the DATA section ([`Parsing::step_in_parallel`]).
struct Piece {
    instances: Vec<(u64, Instance)>,
    /// Where the last instance's `;` ended (the piece's start where it has none).
    end: usize,
    /// The lines up to `end`.
    lines: usize,
    /// Whether something other than an instance came next (ENDSEC).
    stopped: bool,
}

/// Parses the instances from `start` on, until one ends at or past `limit` or something other
/// than an instance comes.
fn parse_piece(bytes: &[u8], start: usize, limit: usize) -> Result<Piece, SyntaxError> {
    let mut p = Parser {
        lexer: Lexer {
            bytes,
            at: start,
            line: 0,
            entity: None,
        },
        peeked: None,
    };
    let mut piece = Piece {
        instances: Vec::new(),
        end: start,
        lines: 0,
        stopped: false,
    };
    while piece.end < limit {
        p.lexer.skip_space()?;
        if bytes.get(p.lexer.at) != Some(&b'#') {
            piece.stopped = true;
            break;
        }
        let Token::Ref(id) = p.next()? else {
            return Err(p.lexer.error("expected an instance"));
        };
        piece.instances.push((id, p.instance(id)?));
        piece.end = p.lexer.at;
        piece.lines = p.lexer.line;
    }
    Ok(piece)
}

/// The first place after `from` (and before `end`) just past a `;` that white space and a `#`
/// follow: where an instance likely starts.
fn instance_start_after(bytes: &[u8], from: usize, end: usize) -> Option<usize> {
    let mut at = from;
    while at < end {
        let semicolon = at + bytes.get(at..end)?.iter().position(|&b| b == b';')?;
        let after = semicolon + 1;
        let next = bytes
            .get(after..)?
            .iter()
            .position(|b| !b.is_ascii_whitespace())
            .map(|k| after + k);
        if next.is_some_and(|k| bytes[k] == b'#') {
            return Some(after);
        }
        at = after;
    }
    None
}

fn describe(t: &Token) -> String {
    match t {
        Token::Keyword(k) => k.clone(),
        Token::Ref(id) => format!("#{id}"),
        Token::Integer(i) => i.to_string(),
        Token::Real(x) => x.to_string(),
        Token::Str(_) => "a string".into(),
        Token::Enum(e) => format!(".{e}."),
        Token::Binary(_) => "a binary".into(),
        Token::Open => "'('".into(),
        Token::Close => "')'".into(),
        Token::Comma => "','".into(),
        Token::Semicolon => "';'".into(),
        Token::Equals => "'='".into(),
        Token::Dollar => "'$'".into(),
        Token::Star => "'*'".into(),
        Token::End => "the end of the file (the text is truncated?)".into(),
    }
}

/// Whether the bytes start like a Part 21 file (after white space and comments).
pub fn looks_like_part21(bytes: &[u8]) -> bool {
    let mut lexer = Lexer {
        bytes,
        at: 0,
        line: 1,
        entity: None,
    };
    matches!(lexer.next(), Ok(Token::Keyword(k)) if k == "ISO-10303-21")
}

/// Parses a Part 21 file: `ISO-10303-21;`, the HEADER section, one or more DATA sections, and
/// `END-ISO-10303-21;`. `progress(fraction)` is called now and then with the share of the
/// bytes read, and parsing stops (with an error) where it returns false.
pub fn parse(bytes: &[u8], progress: &mut dyn FnMut(f64) -> bool) -> Result<Exchange, SyntaxError> {
    let mut parsing = Parsing::default();
    while !parsing.step(bytes, 4096)? {
        if !progress(parsing.fraction(bytes)) {
            return Err(SyntaxError {
                line: parsing.line,
                entity: None,
                message: "cancelled".into(),
            });
        }
    }
    progress(1.0);
    Ok(parsing.exchange)
}

/// A Part 21 parse that stops after a number of instances and goes on where it stopped, so
/// that a large file is parsed across many frames. It keeps only its place in the bytes (it
/// stops only between instances, where nothing is read ahead), so the bytes are passed to
/// every step.
#[derive(Debug)]
pub struct Parsing {
    at: usize,
    line: usize,
    started: bool,
    in_data: bool,
    saw_data: bool,
    done: bool,
    /// Whether room for the file's instances was set aside ([`Self::reserve`]).
    reserved: bool,
    exchange: Exchange,
}

impl Default for Parsing {
    fn default() -> Self {
        Self {
            at: 0,
            line: 1,
            started: false,
            in_data: false,
            saw_data: false,
            done: false,
            reserved: false,
            exchange: Exchange::default(),
        }
    }
}

/// The instances read before the file's count is estimated from their bytes.
const RESERVE_AFTER_INSTANCES: usize = 1024;

impl Parsing {
    /// The share of `bytes` read.
    pub fn fraction(&self, bytes: &[u8]) -> f64 {
        self.at as f64 / bytes.len().max(1) as f64
    }

    /// Parses on through at most `instances` more instances of `bytes` (the same bytes every
    /// time) on each core ([`Self::step_in_parallel`]); true once the file has ended.
    pub fn step(&mut self, bytes: &[u8], instances: usize) -> Result<bool, SyntaxError> {
        if self.done {
            return Ok(true);
        }
        self.reserve(bytes);
        if self.step_in_parallel(bytes, instances) {
            return Ok(false);
        }
        let mut p = Parser {
            lexer: Lexer {
                bytes,
                at: self.at,
                line: self.line,
                entity: None,
            },
            peeked: None,
        };
        let result = self.run(&mut p, instances);
        self.at = p.lexer.at;
        self.line = p.lexer.line;
        result
    }

    /// Once [`RESERVE_AFTER_INSTANCES`] instances are read: room for the file's instances as
    /// many as their bytes so far say the rest of the file holds, and a tenth more, set aside
    /// at once. Grown by doubling instead, the list of a 1,000,000-instance file was copied
    /// whole in one step (a 0.1–0.2 s step on the 2-core machine at 524,288 instances, where
    /// a step is otherwise 10–20 ms), the frame that step fell in waiting for it.
    fn reserve(&mut self, bytes: &[u8]) {
        let parsed = self.exchange.instances.len();
        if self.reserved || !self.in_data || parsed < RESERVE_AFTER_INSTANCES {
            return;
        }
        self.reserved = true;
        // At least 32 bytes an instance (`#12=A(#10,#11);` and its line end are 16), so that a
        // file of tiny first instances does not set aside room for millions.
        let per_instance = (self.at / parsed).max(32);
        let rest = bytes.len().saturating_sub(self.at) / per_instance;
        let total = (parsed + rest + rest / 10).min(MAX_ENTITIES);
        let x = &mut self.exchange;
        x.instances.reserve(total.saturating_sub(parsed));
        x.index.reserve(total);
    }

    /// Inside the DATA section, with more than one thread and a large enough file: parses
    /// the next `instances` instances for each thread, the text cut into pieces that each
    /// thread parses on its own, and keeps what is sure to be the parse from the start.
    ///
    /// A piece starts after a `;` that is followed by `#`, which is where an instance most
    /// likely begins but need not be (inside a string). The first piece starts where the
    /// parse stands, between instances. A piece's instances are kept when its start is
    /// between instances; the next piece's start is then too if this piece's last instance
    /// ends exactly there. The parse is thus the one-thread parse, bit for bit: the pieces
    /// kept are in order, and the first piece not kept (one that ran past the next piece's
    /// start, met an error, a number used twice or ENDSEC) is parsed again by the one-thread
    /// parse, which reports any error with its line. False where nothing was kept.
    fn step_in_parallel(&mut self, bytes: &[u8], instances: usize) -> bool {
        let threads = crate::kernel::par::threads();
        let parsed = self.exchange.instances.len();
        if !self.in_data || threads < 2 || parsed == 0 || bytes.len() < PARALLEL_PARSE_BYTES {
            return false;
        }
        // The bytes an instance has taken so far (the header's too: a slight overestimate).
        let per_instance = (self.at / parsed).clamp(16, 1 << 16);
        let end = bytes
            .len()
            .min(self.at + per_instance * instances.max(1) * threads);
        let pieces = 2 * threads;
        let mut starts = vec![self.at];
        for k in 1..pieces {
            let from = self.at + (end - self.at) * k / pieces;
            let last = starts.last().copied().unwrap_or(self.at);
            if let Some(b) = instance_start_after(bytes, from.max(last + 1), end)
                && b > last
            {
                starts.push(b);
            }
        }
        let limit = |k: usize| starts.get(k + 1).copied().unwrap_or(end);
        let parsed_pieces =
            crate::kernel::par::map(starts.len(), |k| parse_piece(bytes, starts[k], limit(k)));
        let mut kept = false;
        for (k, piece) in parsed_pieces.into_iter().enumerate() {
            let Ok(piece) = piece else { break };
            if piece.instances.is_empty() || !self.keep(piece.instances) {
                break;
            }
            kept = true;
            self.at = piece.end;
            self.line += piece.lines;
            if piece.stopped || piece.end != limit(k) {
                break;
            }
        }
        kept
    }

    /// Appends a piece's instances to the exchange; false (and the exchange unchanged) where
    /// one of their numbers is taken or the file would have too many instances.
    fn keep(&mut self, instances: Vec<(u64, Instance)>) -> bool {
        let x = &mut self.exchange;
        if x.instances.len() + instances.len() > MAX_ENTITIES {
            return false;
        }
        let first = x.instances.len();
        for (k, (id, _)) in instances.iter().enumerate() {
            if !x.index.insert(*id, first + k) {
                // Undone: the one-thread parse reports the number used twice, with its line.
                for (id, _) in &instances[..k] {
                    x.index.remove(*id);
                }
                return false;
            }
        }
        x.instances.extend(instances);
        true
    }

    /// The exchange parsed (complete once [`Self::step`] returned true).
    pub fn finish(self) -> Exchange {
        self.exchange
    }

    fn run(&mut self, p: &mut Parser, budget: usize) -> Result<bool, SyntaxError> {
        if !self.started {
            match p.next()? {
                Token::Keyword(k) if k == "ISO-10303-21" => {}
                _ => {
                    return Err(SyntaxError {
                        line: 1,
                        entity: None,
                        message: "not an ISO-10303-21 file: it does not start with ISO-10303-21;"
                            .into(),
                    });
                }
            }
            p.expect(Token::Semicolon, "';' after ISO-10303-21")?;
            self.started = true;
        }
        let exchange = &mut self.exchange;
        let mut count = 0usize;
        loop {
            if self.in_data {
                match p.next()? {
                    Token::Ref(id) => {
                        let instance = p.instance(id)?;
                        if !exchange.index.insert(id, exchange.instances.len()) {
                            return Err(SyntaxError {
                                line: p.lexer.line,
                                entity: Some(id),
                                message: "the instance number is used twice".into(),
                            });
                        }
                        exchange.instances.push((id, instance));
                        if exchange.instances.len() > MAX_ENTITIES {
                            return Err(p
                                .lexer
                                .error(format!("more than {MAX_ENTITIES} instances")));
                        }
                        count += 1;
                        if count >= budget {
                            // Between instances: nothing was read ahead.
                            return Ok(false);
                        }
                    }
                    Token::Keyword(k) if k == "ENDSEC" => {
                        p.expect(Token::Semicolon, "';' after ENDSEC")?;
                        self.in_data = false;
                    }
                    Token::End => {
                        return Err(p.lexer.error(
                            "the file ends inside its DATA section (the text is truncated?)",
                        ));
                    }
                    other => {
                        return Err(p.lexer.error(format!(
                            "expected an instance (#123 = ...) or ENDSEC, found {}",
                            describe(&other)
                        )));
                    }
                }
                continue;
            }
            match p.next()? {
                Token::Keyword(k) if k == "HEADER" => {
                    p.expect(Token::Semicolon, "';' after HEADER")?;
                    exchange.header.extend(p.header()?);
                }
                Token::Keyword(k) if k == "DATA" => {
                    // DATA may carry a name and schema list in Part 21 edition 3.
                    if p.peek()? == &Token::Open {
                        p.next()?;
                        p.list_items(1)?;
                    }
                    p.expect(Token::Semicolon, "';' after DATA")?;
                    self.saw_data = true;
                    self.in_data = true;
                }
                Token::Keyword(k) if k == "END-ISO-10303-21" => {
                    if !self.saw_data {
                        return Err(p.lexer.error("the file has no DATA section"));
                    }
                    self.done = true;
                    return Ok(true);
                }
                Token::Keyword(k) if k == "ANCHOR" || k == "REFERENCE" || k == "SIGNATURE" => {
                    // Edition 3 sections knotwork does not use: skip to their ENDSEC.
                    loop {
                        match p.next()? {
                            Token::Keyword(e) if e == "ENDSEC" => break,
                            Token::End => {
                                return Err(p.lexer.error(format!("the {k} section never ends")));
                            }
                            _ => {}
                        }
                    }
                }
                Token::End => {
                    return Err(p.lexer.error(
                        "the file ends without END-ISO-10303-21; (the text is truncated?)",
                    ));
                }
                other => {
                    return Err(p
                        .lexer
                        .error(format!("expected a section, found {}", describe(&other))));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_text(text: &str) -> Result<Exchange, SyntaxError> {
        parse(text.as_bytes(), &mut |_| true)
    }

    const SMALL: &str = "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('x'),'2;1');\nFILE_NAME('a.step','2026-01-01T00:00:00',(''),(''),'','','');\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\n/* a comment */\n#1 = CARTESIAN_POINT('it''s',(0.,1.5,-2.E-1));\n#2=(BOUNDED_CURVE()B_SPLINE_CURVE(1,(#1,#1),.UNSPECIFIED.,.F.,.F.)CURVE());\n#3 = MEASURE(LENGTH_MEASURE(25.4),#2,$,*);\n#4 = NAME('\\X2\\00E9\\X0\\t\\X\\E9');\nENDSEC;\nEND-ISO-10303-21;\n";

    #[test]
    fn reads_simple_complex_and_typed_instances() {
        let x = parse_text(SMALL).unwrap();
        assert_eq!(x.instances.len(), 4);
        assert_eq!(
            x.schemas(),
            vec!["AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }"]
        );
        let Some(Instance::Simple(p)) = x.get(1) else {
            panic!()
        };
        assert_eq!(p.args[0], Value::Str("it's".into()));
        assert_eq!(
            p.args[1],
            Value::List(vec![Value::Real(0.0), Value::Real(1.5), Value::Real(-0.2)])
        );
        let c = x.get(2).unwrap();
        assert!(c.is("B_SPLINE_CURVE") && c.is("CURVE") && !c.is("LINE"));
        assert_eq!(c.part("B_SPLINE_CURVE").unwrap().args[0], Value::Integer(1));
        let Some(Instance::Simple(m)) = x.get(3) else {
            panic!()
        };
        assert_eq!(
            m.args[0],
            Value::Typed("LENGTH_MEASURE".into(), Box::new(Value::Real(25.4)))
        );
        assert_eq!(m.args[2], Value::Null);
        assert_eq!(m.args[3], Value::Derived);
        let Some(Instance::Simple(n)) = x.get(4) else {
            panic!()
        };
        assert_eq!(n.args[0], Value::Str("été".into()));
    }

    #[test]
    fn a_parse_in_steps_of_one_instance_is_the_parse_at_once() {
        let at_once = parse_text(SMALL).unwrap();
        let mut parsing = Parsing::default();
        let mut steps = 0;
        while !parsing.step(SMALL.as_bytes(), 1).unwrap() {
            steps += 1;
            assert!(parsing.fraction(SMALL.as_bytes()) < 1.0);
        }
        // One step per instance, and the last also reads to the end.
        assert_eq!(steps, 4);
        let x = parsing.finish();
        assert_eq!(x.header, at_once.header);
        assert_eq!(x.instances, at_once.instances);
        assert_eq!(x.get(3), at_once.get(3));
        // An error after a stop names the line and instance where it is.
        let bad = SMALL.replace("#4 = NAME(", "#4 = NAME((");
        let mut parsing = Parsing::default();
        let e = loop {
            match parsing.step(bad.as_bytes(), 1) {
                Ok(true) => panic!("accepted"),
                Ok(false) => {}
                Err(e) => break e,
            }
        };
        assert_eq!(e, parse_text(&bad).unwrap_err());
    }

    #[test]
    fn escapes_next_to_bytes_that_are_not_ascii_decode_without_panicking() {
        for raw in [
            &b"\\X2\\00\xe9\xe9\\X0\\"[..],
            b"\\X\\\xe9",
            b"ab\\X4\\0001F600\\X0\\\xff\\",
            b"\\X2\\D800\\X0\\",
        ] {
            let _ = decode_string(raw);
        }
        assert_eq!(decode_string(b"\\X4\\0001F600\\X0\\"), "\u{1F600}");
    }

    #[test]
    fn refuses_what_is_not_part21_or_is_cut_short() {
        let e = parse_text("solid x\nfacet normal 0 0 1\n").unwrap_err();
        assert!(e.message.starts_with("not an ISO-10303-21 file"), "{e}");
        for cut in [SMALL.len() / 2, SMALL.len() - 20, SMALL.len() - 3] {
            let e = parse_text(&SMALL[..cut]).unwrap_err();
            assert!(!e.message.is_empty());
        }
        let e = parse_text(&SMALL.replace("#3 = MEASURE(", "#3 = MEASURE((((")).unwrap_err();
        assert_eq!(e.entity, Some(3), "{e}");
        let deep = format!(
            "ISO-10303-21;HEADER;ENDSEC;DATA;#1=A({}1{});ENDSEC;END-ISO-10303-21;",
            "(".repeat(100),
            ")".repeat(100)
        );
        assert!(parse_text(&deep).unwrap_err().message.contains("nested"));
        let twice = SMALL.replace("#4 =", "#1 =");
        assert!(parse_text(&twice).unwrap_err().message.contains("twice"));
    }

    use crate::kernel::par;
    use std::fmt::Write as _;

    /// A file of `count` instances in general position for the parser: numbers out of order
    /// and with gaps, strings holding `;`, `#`, quotes and line breaks (instance starts, to a
    /// quick look, inside strings and comments), comments between instances, complex
    /// instances, instances over several lines, CR LF line ends and a second DATA section.
    fn tricky_file(count: usize, seed: u64, tricky: bool) -> String {
        let mut state = seed;
        let mut next = move |n: usize| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as usize % n
        };
        let mut ids: Vec<usize> = (0..count).map(|k| 3 * k + 1 + next(3)).collect();
        for _ in 0..count / 4 {
            let (a, b) = (next(count), next(count));
            ids.swap(a, b);
        }
        let mut text = String::from(
            "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('tricky;\n#1=A();'),'2;1');\n\
             FILE_NAME('t.step','',(''),(''),'','','');\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\n\
             ENDSEC;\nDATA;\n",
        );
        for (k, id) in ids.iter().enumerate() {
            if k == count / 2 {
                text.push_str("ENDSEC;\nDATA;\n");
            }
            let r = ids[next(count)];
            let _ = match if tricky { next(6) } else { 0 } {
                0 => writeln!(
                    text,
                    "#{id}=CARTESIAN_POINT('',({}.5,-{}.25E-1,{}.));",
                    next(1000),
                    next(99),
                    next(7)
                ),
                1 => writeln!(text, "#{id}=NAME('a;\n#{r}=B(1);', 'it''s; #{r}=', $);"),
                2 => writeln!(text, "#{id}=(A(1) B('x;\n #{r}') C());"),
                3 => writeln!(
                    text,
                    "/* ;\n#{r}=X(); */ #{id} =\n  EDGE(#{r},\n (1,2,(3)),.T.)\n;"
                ),
                4 => writeln!(
                    text,
                    "#{id}=S('{}');",
                    format!(";\n#{r}=Q('')").repeat(1 + next(400))
                ),
                _ => write!(text, "#{id}=REF(#{r},*,$,.UNSPECIFIED.);\r\n"),
            };
        }
        text.push_str("ENDSEC;\nEND-ISO-10303-21;\n");
        text
    }

    fn parse_on(helpers: par::Helpers, bytes: &[u8]) -> Result<Exchange, SyntaxError> {
        par::with_helpers(helpers, || parse(bytes, &mut |_| true))
    }

    fn assert_same(one: &Exchange, many: &Exchange) {
        assert_eq!(one.header, many.header);
        assert_eq!(one.instances.len(), many.instances.len());
        assert!(one.instances == many.instances);
        for (id, instance) in &one.instances {
            assert_eq!(many.get(*id), Some(instance));
        }
    }

    #[test]
    fn a_parse_on_four_threads_is_the_parse_on_one() {
        for (seed, tricky) in [(1, true), (2, true), (3, true), (4, false)] {
            let text = tricky_file(12_000, seed, tricky);
            assert!(text.len() > 2 * PARALLEL_PARSE_BYTES);
            let one = parse_on(par::ONE_THREAD, text.as_bytes()).unwrap();
            let many = parse_on(par::SCOPED_HELPERS, text.as_bytes()).unwrap();
            assert_eq!(one.instances.len(), 12_000);
            assert_same(&one, &many);
            // The editor's steps, a few hundred instances a thread each.
            let (stepped, steps) = par::with_helpers(par::SCOPED_HELPERS, || {
                let mut parsing = Parsing::default();
                let mut steps = 0;
                while !parsing.step(text.as_bytes(), 300).unwrap() {
                    steps += 1;
                }
                (parsing.finish(), steps)
            });
            assert_same(&one, &stepped);
            // Without strings that look like instance starts, every piece is kept.
            if !tricky {
                assert!(
                    steps < 12_000 / 600,
                    "{steps} steps: too few kept in parallel"
                );
            }
        }
    }

    #[test]
    fn an_error_on_four_threads_is_the_error_on_one() {
        let text = tricky_file(12_000, 7, true);
        // Before an instance (no string holds a point).
        let at = |share: f64| {
            let k = (text.len() as f64 * share) as usize;
            let point = k + text[k..].find("=CARTESIAN_POINT").unwrap();
            text[..point].rfind('\n').unwrap() + 1
        };
        let mut broken = Vec::new();
        // A parameter list with a hole, a number used twice, a string never closed, an
        // unknown character: each late in the file, where a thread other than the first
        // meets it.
        for (share, insert) in [
            (0.7, "#1=FOO(1,,2);\n"),
            (0.8, "#5=FOO(1);\n#5=FOO(2);\n"),
            (0.9, "#3=FOO((1,2);\n"),
            (0.95, "#4=FOO(@);\n"),
        ] {
            let k = at(share);
            broken.push(format!("{}{insert}{}", &text[..k], &text[k..]));
        }
        for text in broken {
            let (Err(one), Err(many)) = (
                parse_on(par::ONE_THREAD, text.as_bytes()),
                parse_on(par::SCOPED_HELPERS, text.as_bytes()),
            ) else {
                panic!("a broken file parsed");
            };
            assert_eq!(one, many);
            assert!(one.line > 1000, "{one}");
        }
    }

    #[test]
    fn the_index_finds_numbers_near_and_far() {
        let mut index = InstanceIndex::default();
        let ids = [1u64, 0, 70_000, 5, 1 << 40, u64::MAX, 200_000, 3];
        for (at, id) in ids.iter().enumerate() {
            assert!(index.insert(*id, at), "#{id}");
        }
        for (at, id) in ids.iter().enumerate() {
            assert_eq!(index.get(*id), Some(at), "#{id}");
            assert!(!index.insert(*id, 99), "#{id} taken twice");
        }
        assert_eq!(index.get(2), None);
        assert_eq!(index.get(u64::MAX - 1), None);
        // A number too far for the table when read stays found once the table reaches it.
        for at in ids.len()..200_000 {
            assert!(index.insert(1_000_000 + at as u64, at));
        }
        assert_eq!(index.get(200_000), Some(6));
        index.remove(200_000);
        index.remove(5);
        assert_eq!((index.get(200_000), index.get(5)), (None, None));
        assert!(index.insert(5, 42));
        assert_eq!(index.get(5), Some(42));
    }
}
