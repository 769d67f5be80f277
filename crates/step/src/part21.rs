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
    index: HashMap<u64, usize>,
}

impl Exchange {
    pub fn get(&self, id: u64) -> Option<&Instance> {
        self.index.get(&id).map(|&k| &self.instances[k].1)
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

    /// `NAME(args)`: the name has been read.
    fn record(&mut self, name: String, depth: usize) -> Result<Record, SyntaxError> {
        self.expect(Token::Open, &format!("'(' after {name}"))?;
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
                self.expect(Token::Open, &format!("'(' after {name}"))?;
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
            exchange: Exchange::default(),
        }
    }
}

impl Parsing {
    /// The share of `bytes` read.
    pub fn fraction(&self, bytes: &[u8]) -> f64 {
        self.at as f64 / bytes.len().max(1) as f64
    }

    /// Parses on through at most `instances` more instances of `bytes` (the same bytes every
    /// time); true once the file has ended.
    pub fn step(&mut self, bytes: &[u8], instances: usize) -> Result<bool, SyntaxError> {
        if self.done {
            return Ok(true);
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
                        if exchange
                            .index
                            .insert(id, exchange.instances.len())
                            .is_some()
                        {
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
}
