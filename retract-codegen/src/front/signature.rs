//! The attribute and the signature: order k, dimension n, parameters.
//!
//! Limits, each a `syn::Error` at the type beyond it (never an out-of-memory abort): order
//! k <= [`MAX_ORDER`] = 4; dimension times order n k <= [`MAX_UNKNOWNS`] = 64 (n <= 64 at
//! order 1, 32 at order 2, 21 at order 3, 16 at order 4), since the expansion grows faster
//! than (n k)^2 (measured, release build: a dense Hessian at n k = 64 expands in 0.4-1.7 s,
//! at n k = 128 in 5-8 s and 250 MB; n = 1000 at order 1 took 10 minutes and 4.9 GB); array
//! lengths `[f64; M]` and `&[[f64; M]]` of parameters M <= [`MAX_LEN`] = 4 294 967 295, so
//! that every index fits the graph's u32 (they cost nothing to expand: only the indices that
//! are read become symbols).

use proc_macro2::{Span, TokenStream};
use syn::spanned::Spanned;
use syn::{FnArg, Ident, ItemFn, Pat, ReturnType, Type};

use crate::charts::Space;
use crate::util::ErrorContext;

/// Highest supported order.
pub const MAX_ORDER: usize = 4;

/// Largest n k, the dimension times the order: the number of unknowns of a step's Newton
/// system; the expansion's time and size grow faster than its square.
pub const MAX_UNKNOWNS: usize = 64;

/// Longest parameter array `[f64; M]` or list element `&[[f64; M]]`: indices are u32.
pub const MAX_LEN: usize = u32::MAX as usize;

/// What an argument of the Lagrangian is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `f64`
    Scalar,
    /// `[f64; len]`
    Array(usize),
    /// `&[[f64; len]]`: any number of elements, summed over by run-time loops.
    Slice(usize),
}

impl Kind {
    fn describe(self) -> String {
        match self {
            Kind::Scalar => "f64".into(),
            Kind::Array(n) => format!("[f64; {n}]"),
            Kind::Slice(n) => format!("&[[f64; {n}]]"),
        }
    }
}

/// The attribute being expanded, for its options and its messages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Attribute {
    /// `#[higher_order_lagrangian]`: a Lagrangian and its integrator.
    Lagrangian,
    /// `#[jet_function]`: a scalar function of the jet with its gradient and Hessian.
    JetFunction,
    /// `#[discretization_map]`: a map (q, v) -> (R1, R2), lifted to T^(k-1)Q.
    Map,
    /// `#[mechanical_system]`: a mechanical Lagrangian l(q, q') = T - V into its
    /// Euler-Lagrange operator and the optimal-control Lagrangian of order 2.
    Mechanical,
}

impl Attribute {
    /// The attribute's name.
    pub fn name(self) -> &'static str {
        match self {
            Attribute::Lagrangian => "higher_order_lagrangian",
            Attribute::JetFunction => "jet_function",
            Attribute::Map => "discretization_map",
            Attribute::Mechanical => "mechanical_system",
        }
    }

    /// A message written for a Lagrangian, reworded for the function this attribute takes.
    pub fn reword(self, msg: String) -> String {
        match self {
            Attribute::Lagrangian | Attribute::Mechanical => msg,
            Attribute::JetFunction => msg.replace("Lagrangian", "jet function"),
            Attribute::Map => msg.replace("Lagrangian", "discretization map"),
        }
    }

    /// How many arguments come before the parameters: the jet q, ..., q^(k), or (q, v).
    fn jet_count(self, order: usize) -> usize {
        match self {
            Attribute::Map => 2,
            _ => order + 1,
        }
    }
}

/// A parameter: an argument after the jet.
#[derive(Clone, Debug)]
pub struct Param {
    pub name: Ident,
    pub kind: Kind,
}

/// The attribute and signature, checked.
#[derive(Clone, Debug)]
pub struct Signature {
    /// Order k.
    pub order: usize,
    /// Dimension n.
    pub dim: usize,
    /// Whether the jet arguments are plain `f64` (n = 1).
    pub scalar_jet: bool,
    /// Names of q, q', ..., q^(k).
    pub jet: Vec<Ident>,
    /// Parameters, in order.
    pub params: Vec<Param>,
    /// Name of the generated type.
    pub type_name: Ident,
    /// Whether the domain check (singularity guard) is emitted.
    pub guard: bool,
    /// Whether a discretization map's conditions are checked at compile time (`check`).
    pub check: bool,
    /// Where the Lagrangian lives: R^n, the unit sphere (`sphere`), SO(3) (`so3`) or SE(3)
    /// (`se3`); on the last three the generated system works in a chart whose frame is a parameter.
    pub space: Space,
    /// The attribute that is expanded.
    pub attribute: Attribute,
    /// The number m of components of a jet function returning `[f64; m]`; `None` for a
    /// scalar (every Lagrangian, and a jet function returning `f64`).
    pub components: Option<usize>,
}

impl Signature {
    /// The signature of the function composed with the chart of its space: the chart's
    /// dimension (`Chart::chart_dim`) and the parameters followed by the chart's frame;
    /// unchanged on R^n.
    pub fn in_chart(&self) -> Signature {
        let chart = self.space.chart();
        let mut sig = self.clone();
        sig.dim = chart.chart_dim(self.dim);
        if let Some(frame) = chart.frame() {
            sig.params.push(Param {
                name: Ident::new(frame.name, Span::call_site()),
                kind: Kind::Array(frame.len),
            });
        }
        sig
    }

    /// The number of components of jet argument `order` as written: 9 for the rotation of
    /// `so3`, 12 for the pose of `se3`, else the dimension n.
    pub fn jet_len(&self, order: u8) -> usize {
        match self.space.chart().body_coordinates() {
            Some((group, _)) if order == 0 => group,
            _ => self.dim,
        }
    }
}

/// Options of the attribute.
struct Options {
    order: Option<(usize, Span)>,
    name: Option<Ident>,
    guard: bool,
    check: bool,
    space: Option<(Space, Span)>,
}

fn parse_options(attr: TokenStream, attribute: Attribute) -> syn::Result<Options> {
    let mut options = Options {
        order: None,
        name: None,
        guard: true,
        check: true,
        space: None,
    };
    let parser = syn::meta::parser(|meta| {
        if meta.path.is_ident("order") {
            let lit: syn::LitInt = meta.value()?.parse()?;
            let k: usize = lit.base10_parse()?;
            if !(1..=MAX_ORDER).contains(&k) {
                return Err(syn::Error::new(
                    lit.span(),
                    format!("unsupported order {k}; supported: order = 1..={MAX_ORDER}"),
                ));
            }
            options.order = Some((k, lit.span()));
            Ok(())
        } else if meta.path.is_ident("name") {
            options.name = Some(meta.value()?.parse()?);
            Ok(())
        } else if meta.path.is_ident("helpers") && attribute != Attribute::Map {
            // (read by `helper::helper_names`; here only skipped)
            let _: syn::Expr = meta.value()?.parse()?;
            Ok(())
        } else if attribute == Attribute::Mechanical
            && crate::front::actuation::OPTIONS
                .iter()
                .any(|name| meta.path.is_ident(name))
        {
            // (read by `front::actuation`; here only skipped)
            let _: syn::Expr = meta.value()?.parse()?;
            Ok(())
        } else if meta.path.is_ident("guard")
            && matches!(attribute, Attribute::Lagrangian | Attribute::Mechanical)
        {
            let lit: syn::LitBool = meta.value()?.parse()?;
            options.guard = lit.value;
            Ok(())
        } else if let Some((space, option)) = Space::OPTIONS
            .into_iter()
            .filter_map(|space| Some((space, space.chart().option()?)))
            .find(|(_, option)| {
                meta.path.is_ident(option)
                    && !matches!(attribute, Attribute::Map | Attribute::Mechanical)
            })
        {
            if let Some((other, _)) = options.space.filter(|(other, _)| *other != space) {
                return Err(meta.error(format!(
                    "`{}` and `{option}` exclude each other: a Lagrangian lives on one space",
                    other.chart().option().unwrap_or_default(),
                )));
            }
            options.space = Some((space, meta.path.span()));
            Ok(())
        } else if meta.path.is_ident("check") && attribute == Attribute::Map {
            let lit: syn::LitBool = meta.value()?.parse()?;
            options.check = lit.value;
            Ok(())
        } else if attribute == Attribute::Map {
            Err(meta.error(
                "unsupported option; supported: `order = k` (1..=4), `name = TypeName`, \
                 `check = false`",
            ))
        } else if attribute == Attribute::Mechanical {
            Err(meta.error(
                "unsupported option; supported: `actuated = [i, ...]`, `input_matrix = f`, \
                 `forces = f`, `cost = f`, `weight = R`, `name = TypeName`, `guard = false`, \
                 `helpers = [...]`, `order = 1`",
            ))
        } else if attribute == Attribute::Lagrangian {
            Err(meta.error(format!(
                "unsupported option; supported: `order = k` (1..=4), `name = TypeName`, \
                 `guard = false`, {}",
                Space::option_list(", ", ", ")
            )))
        } else {
            Err(meta.error(format!(
                "unsupported option; supported: `order = k` (1..=4), `name = TypeName`, {}",
                Space::option_list(", ", ", ")
            )))
        }
    });
    syn::parse::Parser::parse2(parser, attr)?;
    Ok(options)
}

fn kind_of(ty: &Type) -> Option<Kind> {
    fn is_f64(ty: &Type) -> bool {
        matches!(ty, Type::Path(p) if p.qself.is_none() && p.path.is_ident("f64"))
    }
    fn array_len(ty: &Type) -> Option<usize> {
        // (a length passed through `macro_rules!` arrives in an invisible group)
        fn literal(len: &syn::Expr) -> Option<usize> {
            match len {
                syn::Expr::Lit(syn::ExprLit {
                    lit: syn::Lit::Int(n),
                    ..
                }) => n.base10_parse().ok().filter(|&n: &usize| n > 0),
                syn::Expr::Group(g) => literal(&g.expr),
                _ => None,
            }
        }
        match ty {
            Type::Array(a) if is_f64(&a.elem) => literal(&a.len),
            _ => None,
        }
    }
    match ty {
        _ if is_f64(ty) => Some(Kind::Scalar),
        Type::Array(_) => array_len(ty).map(Kind::Array),
        Type::Reference(r) if r.mutability.is_none() => match &*r.elem {
            Type::Slice(s) => array_len(&s.elem).map(Kind::Slice),
            _ => None,
        },
        _ => None,
    }
}

/// "UpperCamelCase" of a snake_case name, or an error at the name when that is not an
/// identifier of a type (`_1` gives `1`, `_2d_arm` gives `2dArm`, `self_` gives `Self`).
fn camel(name: &Ident, attribute: Attribute) -> syn::Result<Ident> {
    let s: String = name
        .to_string()
        .trim_start_matches("r#")
        .split('_')
        .filter(|w| !w.is_empty())
        .map(|w| {
            let mut c = w.chars();
            match c.next() {
                Some(f) => f.to_uppercase().chain(c).collect::<String>(),
                None => String::new(),
            }
        })
        .collect();
    let s = if s.is_empty() { "Lagrangian".into() } else { s };
    // syn rejects what is not an identifier and the keywords (`Self`), without panicking
    match syn::parse_str::<Ident>(&s) {
        Ok(ident) => Ok(Ident::new(&ident.to_string(), name.span())),
        Err(_) => {
            let why = if s.starts_with(|c: char| c.is_ascii_digit()) {
                "a type name cannot start with a digit"
            } else {
                "it is a keyword or not an identifier"
            };
            Err(syn::Error::new(
                name.span(),
                format!(
                    "the generated type is named after the function in UpperCamelCase, but \
                     `{name}` gives `{s}`, which is not a valid type name ({why}); name the type \
                     with #[{}(order = k, name = TypeName)] or rename the function",
                    attribute.name()
                ),
            ))
        }
    }
}

/// The errors of a signature, collected so that the user sees all of them, with the
/// messages written for a Lagrangian reworded for the attribute.
struct Errors {
    attribute: Attribute,
    list: ErrorContext,
}

impl Errors {
    fn fail(&mut self, span: Span, msg: String) {
        self.list.error(span, self.attribute.reword(msg));
    }
}

/// The function's qualifiers, generics and (except for a map: [`check_map_return`]) return
/// type: errors for `const`, `async`, `unsafe`, generic parameters and a return type other
/// than `f64`.
fn check_qualifiers(sig: &syn::Signature, errors: &mut Errors) {
    if let Some(c) = &sig.constness {
        errors.fail(c.span(), "a Lagrangian cannot be a `const fn`".into());
    }
    if let Some(a) = &sig.asyncness {
        errors.fail(a.span(), "a Lagrangian cannot be `async`".into());
    }
    if let Some(u) = &sig.unsafety {
        errors.fail(u.span(), "a Lagrangian cannot be `unsafe`".into());
    }
    if !sig.generics.params.is_empty() || sig.generics.where_clause.is_some() {
        errors.fail(
            sig.generics.span(),
            "a Lagrangian cannot be generic: write it for f64 and concrete array lengths".into(),
        );
    }
    match &sig.output {
        _ if errors.attribute == Attribute::Map => {}
        ReturnType::Type(_, ty) if kind_of(ty) == Some(Kind::Scalar) => {}
        ReturnType::Type(_, ty) if errors.attribute == Attribute::JetFunction => {
            if vector_components(&sig.output).is_none() {
                errors.fail(
                    ty.span(),
                    format!(
                        "a jet function returns `f64` or `[f64; m]` with 1 <= m <= \
                         {MAX_COMPONENTS} (one bound per component)"
                    ),
                );
            }
        }
        ReturnType::Type(_, ty) => errors.fail(
            ty.span(),
            "a Lagrangian returns a scalar: the return type must be `f64`".into(),
        ),
        ReturnType::Default => errors.fail(
            sig.ident.span(),
            "a Lagrangian returns a scalar: add `-> f64`".into(),
        ),
    }
}

/// The most components of a jet function returning `[f64; m]`.
pub const MAX_COMPONENTS: usize = 64;

/// The length m of a `-> [f64; m]` return type, 1 <= m <= [`MAX_COMPONENTS`].
fn vector_components(output: &ReturnType) -> Option<usize> {
    match output {
        ReturnType::Type(_, ty) => match kind_of(ty) {
            Some(Kind::Array(m)) if m <= MAX_COMPONENTS => Some(m),
            _ => None,
        },
        ReturnType::Default => None,
    }
}

/// The return type of a map: the pair `(T, T)` of points, T the type of q.
fn check_map_return(sig: &syn::Signature, jet_kind: Option<Kind>, errors: &mut Errors) {
    let expected = jet_kind
        .map(Kind::describe)
        .unwrap_or_else(|| "[f64; N]".into());
    let msg = format!(
        "a discretization map returns the pair of points (R1, R2): the return type must be \
         `({expected}, {expected})`, the type of q twice"
    );
    match &sig.output {
        ReturnType::Type(_, ty) => match &**ty {
            Type::Tuple(t)
                if t.elems.len() == 2 && t.elems.iter().all(|e| kind_of(e) == jet_kind) => {}
            _ => errors.fail(ty.span(), msg),
        },
        ReturnType::Default => errors.fail(sig.ident.span(), msg),
    }
}

/// The arguments of the function with their kinds, and the span of the type of the first
/// (the configuration q); errors for `self`, patterns, mutable arguments, unsupported types,
/// parameter arrays beyond [`MAX_LEN`] and parameter lists of a map.
fn arguments(
    sig: &syn::Signature,
    jet_count: usize,
    errors: &mut Errors,
) -> (Vec<(Ident, Kind)>, Span) {
    let mut args: Vec<(Ident, Kind)> = Vec::new();
    let mut jet_span = sig.ident.span();
    for input in &sig.inputs {
        let FnArg::Typed(arg) = input else {
            errors.fail(
                input.span(),
                "a Lagrangian is a free function: `self` is not supported".into(),
            );
            continue;
        };
        let name = match &*arg.pat {
            Pat::Ident(p) if p.by_ref.is_none() && p.subpat.is_none() => {
                if let Some(m) = &p.mutability {
                    errors.fail(
                        m.span(),
                        format!(
                            "parameter `{}` cannot be mutable: the arguments of a Lagrangian \
                             are read-only; copy it into a `let mut` binding",
                            p.ident
                        ),
                    );
                }
                p.ident.clone()
            }
            other => {
                errors.fail(
                    other.span(),
                    "unsupported argument pattern: use a plain name".into(),
                );
                continue;
            }
        };
        match kind_of(&arg.ty) {
            // a parameter (the jet's dimension is checked below)
            Some(Kind::Array(len) | Kind::Slice(len))
                if len > MAX_LEN && args.len() >= jet_count =>
            {
                errors.fail(
                    arg.ty.span(),
                    format!("array length {len} exceeds the supported maximum of {MAX_LEN}"),
                )
            }
            Some(Kind::Slice(_))
                if errors.attribute == Attribute::Map && args.len() >= jet_count =>
            {
                errors.fail(
                    arg.ty.span(),
                    "unsupported parameter type for a discretization map; supported: `f64` and \
                     `[f64; N]`"
                        .into(),
                )
            }
            Some(kind) => {
                if args.is_empty() {
                    jet_span = arg.ty.span();
                }
                args.push((name, kind));
            }
            None => errors.fail(
                arg.ty.span(),
                "unsupported argument type; supported: `f64`, `[f64; N]` with a literal N, \
                 and `&[[f64; N]]` for a parameter list of any length"
                    .into(),
            ),
        }
    }
    (args, jet_span)
}

/// The dimension n from the kind of the first argument, and whether the jet is scalar;
/// errors for a slice and for n k beyond [`MAX_UNKNOWNS`] (at `jet_span`).
fn dimension(
    sig: &syn::Signature,
    jet_kind: Option<Kind>,
    jet_span: Span,
    order: usize,
    errors: &mut Errors,
) -> (usize, bool) {
    match jet_kind {
        Some(Kind::Scalar) => (1, true),
        Some(Kind::Array(n)) if n > MAX_UNKNOWNS / order => {
            errors.fail(
                jet_span,
                format!(
                    "dimension too large: n = {n} at order {order} makes {} unknowns per step, \
                     but at most n k = {MAX_UNKNOWNS} are supported (n <= {} at order {order}), \
                     which keeps the expansion within seconds",
                    n.saturating_mul(order),
                    MAX_UNKNOWNS / order
                ),
            );
            (0, false)
        }
        Some(Kind::Array(n)) => (n, false),
        Some(Kind::Slice(_)) => {
            errors.fail(
                sig.inputs.span(),
                "the first argument is the configuration q: `f64` or `[f64; N]`, not a slice"
                    .into(),
            );
            (0, false)
        }
        None => (0, false),
    }
}

/// The conditions of a space option: the jet arguments have the types the space requires
/// ([`Chart::required_argument`](crate::charts::Chart::required_argument)), and no parameter
/// takes the name of the chart's frame.
fn check_space(
    space: Space,
    args: &[(Ident, Kind)],
    (order, jet_count): (usize, usize),
    errors: &mut Errors,
) {
    let chart = space.chart();
    for (i, (name, kind)) in args.iter().take(order + 1).enumerate() {
        match chart.required_argument(order, i) {
            Some(len) if *kind != Kind::Array(len) => {
                errors.fail(
                    name.span(),
                    chart.wrong_argument(order, i, name, &kind.describe()),
                );
            }
            _ => {}
        }
    }
    let Some(frame) = chart.frame() else {
        return;
    };
    for (name, _) in args.iter().skip(jet_count) {
        if name == frame.name {
            errors.fail(
                name.span(),
                format!(
                    "`{}` is the name of the chart that `{}` adds to the parameters; rename \
                     this parameter",
                    frame.name,
                    chart.option().unwrap_or_default()
                ),
            );
        }
    }
}

/// The names of q, q', ..., q^(order) (the first `order + 1` arguments), or of q and v for
/// a map; errors where one is not of the type of q.
fn jet_names(
    args: &[(Ident, Kind)],
    order: usize,
    jet_kind: Option<Kind>,
    errors: &mut Errors,
) -> Vec<Ident> {
    let count = errors.attribute.jet_count(order);
    if let Some(first) = parameters_first(args, count) {
        let moved: Vec<String> = args[..first]
            .iter()
            .map(|(n, _)| format!("`{n}`"))
            .collect();
        let jet: Vec<String> = args[first..first + count]
            .iter()
            .map(|(n, _)| n.to_string())
            .collect();
        errors.fail(
            args[0].0.span(),
            format!(
                "parameters go after the jet: {} {} before `{}`; write ({}, then the \
                 parameters)",
                moved.join(", "),
                if moved.len() == 1 { "comes" } else { "come" },
                args[first].0,
                jet.join(", ")
            ),
        );
        return args.iter().take(count).map(|(n, _)| n.clone()).collect();
    }
    let mut jet = Vec::new();
    for (i, (name, kind)) in args.iter().take(count).enumerate() {
        if Some(*kind) != jet_kind {
            let expected = jet_kind.map(Kind::describe).unwrap_or_default();
            let msg = if errors.attribute == Attribute::Map {
                format!(
                    "argument 2 (`{name}`) is the tangent vector v: it must have the type of q \
                     ({expected}), not {}",
                    kind.describe()
                )
            } else if matches!(kind, Kind::Array(_)) && matches!(jet_kind, Some(Kind::Array(_))) {
                format!(
                    "inconsistent dimensions across jet arguments: `{name}` is {} but `{}` is \
                     {expected}",
                    kind.describe(),
                    args[0].0
                )
            } else {
                format!(
                    "order = {order} makes argument {} (`{name}`) the derivative q^({i}), which must \
                     have the type of q ({expected}), not {}; check the order",
                    i + 1,
                    kind.describe()
                )
            };
            errors.fail(name.span(), msg);
        }
        jet.push(name.clone());
    }
    jet
}

/// Where the jet starts when parameters were written before it: the first position `s > 0`
/// from which `count` arguments share one array or scalar type that the first argument does
/// not have; `None` when the first argument starts such a run (or none exists).
fn parameters_first(args: &[(Ident, Kind)], count: usize) -> Option<usize> {
    let run = |s: usize| {
        args.get(s..s + count).is_some_and(|jet| {
            !matches!(jet[0].1, Kind::Slice(_)) && jet.iter().all(|(_, k)| *k == jet[0].1)
        })
    };
    if count < 2 || run(0) {
        return None;
    }
    (1..args.len()).find(|&s| run(s) && args[0].1 != args[s].1)
}

/// Checks the attribute and the signature of `item` under `attribute`.
pub fn parse(attr: TokenStream, item: &ItemFn, attribute: Attribute) -> syn::Result<Signature> {
    let options = parse_options(attr, attribute)?;
    let sig = &item.sig;

    let options = match (attribute, options.order) {
        (Attribute::Mechanical, Some((order, span))) if order != 1 => {
            return Err(syn::Error::new(
                span,
                format!(
                    "a mechanical Lagrangian l(q, q') = T - V is of order 1, not {order}: the \
                     attribute derives the terms in q'' (the mass matrix) itself; write \
                     `order = 1` or leave the order out"
                ),
            ));
        }
        (Attribute::Mechanical, None) => Options {
            order: Some((1, Span::call_site())),
            ..options
        },
        _ => options,
    };
    let Some((order, order_span)) = options.order else {
        return Err(syn::Error::new(
            Span::call_site(),
            format!(
                "missing the order: write #[{}(order = k)] with k in 1..=4",
                attribute.name()
            ),
        ));
    };
    let mut errors = Errors {
        attribute,
        list: ErrorContext::new(),
    };
    check_qualifiers(sig, &mut errors);
    let jet_count = attribute.jet_count(order);
    let (args, jet_span) = arguments(sig, jet_count, &mut errors);
    let jet_kind = args.first().map(|(_, k)| *k);
    let space = options.space.map_or(Space::Flat, |(space, _)| space);
    let (dim, scalar_jet) = if let Some((_, rate)) = space.chart().body_coordinates() {
        (rate, false)
    } else {
        dimension(sig, jet_kind, jet_span, order, &mut errors)
    };
    if attribute == Attribute::Map {
        check_map_return(sig, jet_kind, &mut errors);
    }
    if let Some((space, _)) = options.space {
        check_space(space, &args, (order, jet_count), &mut errors);
    }
    if args.len() < jet_count && errors.list.is_empty() {
        let msg = if attribute == Attribute::Map {
            format!(
                "a discretization map takes the point q and the tangent vector v (two arguments \
                 of one type) before its parameters; the signature has {}",
                args.len()
            )
        } else if let Some(msg) = space.chart().missing_arguments(order, args.len()) {
            msg
        } else {
            format!(
                "order = {order} needs {} jet arguments (q, q', ..., q^({order})) of one type; \
                 the signature has {}",
                order + 1,
                args.len()
            )
        };
        errors.fail(order_span, msg);
    }
    let jet = if space.chart().body_coordinates().is_some() {
        // (their types were checked by `check_body`)
        args.iter()
            .take(jet_count)
            .map(|(n, _)| n.clone())
            .collect()
    } else {
        jet_names(&args, order, jet_kind, &mut errors)
    };
    let params = args
        .iter()
        .skip(jet_count)
        .map(|(name, kind)| Param {
            name: name.clone(),
            kind: *kind,
        })
        .collect();

    let type_name = match options.name {
        Some(name) => name,
        None => camel(&sig.ident, attribute).unwrap_or_else(|e| {
            errors.list.push(e);
            Ident::new("Lagrangian", sig.ident.span())
        }),
    };
    errors.list.check()?;
    Ok(Signature {
        order,
        dim,
        scalar_jet,
        jet,
        params,
        type_name,
        guard: options.guard,
        check: options.check,
        space,
        attribute,
        components: match attribute {
            Attribute::JetFunction => vector_components(&sig.output),
            _ => None,
        },
    })
}
