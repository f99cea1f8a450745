//! The Spanish catalogue of diagnostics, keyed by code (issue 34 point 11).
//!
//! [`TITLES`] gives every code its Spanish title (a test fails when a code
//! lacks one). [`MESSAGES`] gives Spanish templates of the messages sites
//! format in English: `{}` in the English pattern stands for a value, `{0}`,
//! `{1}`… in the Spanish template take the values in order. [`PHRASES`]
//! translates the labels and hints that are not tied to one code. A message
//! with no template is shown as `título: English message` (see
//! [`crate::Diagnostic::localized`] and docs/i18n.md).

use crate::Code;

/// The Spanish title of each code, in the order of [`Code::ALL`].
pub const TITLES: &[(Code, &str)] = &[
    (Code::Io, "no se pudo leer o escribir un archivo"),
    (Code::TomlSyntax, "alba.toml no es TOML válido"),
    (
        Code::ConfigField,
        "un ajuste de alba.toml falta, es desconocido o tiene un valor incorrecto",
    ),
    (Code::ProgramFile, "un programa listado en alba.toml no se puede usar"),
    (Code::BoardPin, "una dirección de E/S no tiene pin en la placa"),
    (Code::PlantModel, "un modelo de planta de alba.toml no es válido"),
    (Code::ModbusTag, "una entrada de [modbus.tags] no se puede usar"),
    (Code::UsersFile, "un problema en users.toml"),
    (
        Code::ModbusClients,
        "las reglas de clientes del servidor Modbus no se pueden usar",
    ),
    (Code::OpcuaUsersDeprecated, "[opcua.users] está obsoleto (un aviso)"),
    (Code::CsvSyntax, "un archivo CSV está mal formado"),
    (Code::CsvHeader, "la cabecera de un CSV es incorrecta"),
    (Code::BadTagName, "el nombre de una variable no es válido"),
    (Code::UnknownType, "tipo de dato desconocido"),
    (Code::DuplicateTag, "una variable está declarada dos veces"),
    (Code::BadAddress, "una dirección no es válida"),
    (Code::AddressUsedTwice, "dos variables usan la misma dirección"),
    (
        Code::TypeAddressMismatch,
        "el tipo de la variable no corresponde a su dirección",
    ),
    (
        Code::BadInitialValue,
        "un valor inicial no corresponde al tipo de la variable",
    ),
    (Code::BadRetain, "la columna retain no es un booleano"),
    (Code::ReservedType, "un tipo reservado aún no está disponible"),
    (Code::PidParameter, "un parámetro PID de tags.csv no es válido"),
    (Code::AlarmFile, "alarms.csv no es válido"),
    (Code::ScreenFile, "un archivo de pantalla (hmi/*.json) no es válido"),
    (Code::Syntax, "error de sintaxis de Ladder"),
    (Code::UnknownInstruction, "instrucción desconocida"),
    (Code::Unbalanced, "los corchetes o paréntesis no cierran"),
    (Code::EmptyLeg, "una rama tiene un tramo vacío"),
    (Code::UnterminatedRung, "un peldaño no termina en `;`"),
    (Code::IlSyntax, "error de sintaxis de Lista de Instrucciones (AWL)"),
    (Code::UnknownMnemonic, "instrucción AWL desconocida"),
    (
        Code::LogicStack,
        "la pila lógica no contiene lo que la instrucción necesita",
    ),
    (
        Code::S7Timer,
        "el número de temporizador o contador no corresponde a la instrucción",
    ),
    (Code::LoopStructure, "FOR y NEXT no se corresponden"),
    (Code::IlNotSupported, "una función del S7-200 que Alba aún no tiene"),
    (Code::StSyntax, "error de sintaxis de Texto Estructurado"),
    (Code::StType, "error de tipos en Texto Estructurado"),
    (Code::StName, "un nombre desconocido en Texto Estructurado"),
    (
        Code::StNotSupported,
        "una función de Texto Estructurado que el motor aún no tiene",
    ),
    (
        Code::StDeclaration,
        "una declaración de Texto Estructurado no se puede usar",
    ),
    (Code::UnknownTag, "variable desconocida"),
    (Code::OperandCount, "número de operandos incorrecto"),
    (Code::OperandType, "un operando tiene el tipo equivocado"),
    (Code::NotWritable, "un operando no se puede escribir"),
    (Code::UnknownMember, "la estructura no tiene ese miembro"),
    (Code::MissingLabel, "JMP a una etiqueta que no existe"),
    (Code::DuplicateLabel, "una etiqueta está puesta dos veces"),
    (Code::NoOutput, "un peldaño no tiene instrucción de salida"),
    (Code::LabelNotFirst, "LBL no es la primera instrucción de su peldaño"),
    (Code::BadLiteral, "un literal está mal formado o fuera de rango"),
    (
        Code::ConflictingPreset,
        "un temporizador o contador recibe dos preselecciones distintas",
    ),
    (Code::Expression, "una expresión CPT está mal formada"),
    (
        Code::NotYetSupported,
        "una instrucción reservada aún no está disponible",
    ),
    (Code::StimulusSyntax, "una fila de estímulos está mal formada"),
    (
        Code::StimulusTarget,
        "una fila de estímulos nombra algo que no se puede fijar",
    ),
    (Code::TraceName, "un nombre trazado no es válido"),
    (Code::BadArgument, "un valor de la línea de órdenes no es válido"),
    (Code::NotOnBoard, "el programa no puede ejecutarse en la placa"),
    (Code::DoesNotFit, "el firmware no cabe en la placa"),
    (Code::Toolchain, "no se pudo compilar o cargar el firmware"),
    (Code::PnmlSyntax, "un archivo PNML no es XML bien formado"),
    (
        Code::PnmlStructure,
        "un documento PNML no tiene la estructura de una red",
    ),
    (Code::PnmlDuplicateId, "dos elementos PNML tienen el mismo id"),
    (Code::PnmlArc, "un arco PNML no une un lugar y una transición"),
    (Code::PnmlNumber, "un número PNML está fuera de rango"),
    (Code::PnmlLimit, "un archivo PNML es demasiado grande"),
    (Code::PnmlAlba, "los datos de Alba en un archivo PNML no son válidos"),
    (Code::PnmlIgnored, "se ignoró parte de un archivo PNML (un aviso)"),
    (
        Code::NetMode,
        "un elemento de red no puede ejecutarse en este modo (aún)",
    ),
    (Code::NetGuard, "la guarda de una transición no es válida"),
    (Code::NetPlaceTag, "el `<tag>` de un lugar no se puede escribir"),
    (
        Code::NetTagClash,
        "la variable de marcado de un lugar choca con otra variable",
    ),
    (Code::NetRange, "un marcado o peso no cabe en un DINT"),
    (Code::NetArc, "un arco no se puede usar en una red en modo Petri"),
    (Code::NetElement, "un elemento en modo normal no es válido"),
    (Code::NetScript, "el guion de un elemento Expression no es válido"),
    (Code::SfcSyntax, "un archivo SFC no sigue la sintaxis SFC textual"),
    (Code::SfcStructure, "un diagrama SFC no está bien formado"),
    (Code::SfcAction, "una acción SFC no se puede escribir"),
    (
        Code::ImportFailed,
        "no se puede importar un programa de otra herramienta",
    ),
];

/// Spanish templates of messages, by code: (code, English pattern, Spanish).
pub const MESSAGES: &[(Code, &str, &str)] = &[
    (Code::UnknownTag, "unknown tag `{}`", "variable desconocida `{0}`"),
    (
        Code::UnknownMember,
        "{} `{}` has no member `{}` (members: {})",
        "{0} `{1}` no tiene el miembro `{2}` (miembros: {3})",
    ),
    (
        Code::UnknownMember,
        "`{}` is a {}, not a structure with members",
        "`{0}` es un {1}, no una estructura con miembros",
    ),
    (
        Code::BadAddress,
        "{} is outside this project's I/O image",
        "{0} está fuera de la imagen de E/S de este proyecto",
    ),
    (
        Code::UnknownInstruction,
        "unknown instruction `{}`",
        "instrucción desconocida `{0}`",
    ),
    (
        Code::UnknownMnemonic,
        "unknown instruction `{}`",
        "instrucción desconocida `{0}`",
    ),
    (
        Code::OperandCount,
        "{} takes 3 operands, or 4 with a time base, found {}",
        "{0} lleva 3 operandos, o 4 con base de tiempo; hay {1}",
    ),
    (
        Code::OperandCount,
        "{} takes 1 operand, found {}",
        "{0} lleva 1 operando; hay {1}",
    ),
    (
        Code::OperandCount,
        "{} takes {} operands, found {}",
        "{0} lleva {1} operandos; hay {2}",
    ),
    (
        Code::OperandType,
        "{} expects {} here, found {} `{}`",
        "{0} espera aquí {1}; hay {2} `{3}`",
    ),
    (
        Code::NotWritable,
        "`{}` cannot be written: {}",
        "`{0}` no se puede escribir: {1}",
    ),
    (
        Code::NotWritable,
        "`{}` is a literal and cannot be written",
        "`{0}` es un literal y no se puede escribir",
    ),
    (
        Code::NoOutput,
        "this rung has no output instruction",
        "este peldaño no tiene instrucción de salida",
    ),
    (
        Code::NoOutput,
        "the rung ends with the input instruction {}",
        "el peldaño termina con la instrucción de entrada {0}",
    ),
    (
        Code::Unbalanced,
        "this branch is never closed",
        "esta rama nunca se cierra",
    ),
    (
        Code::Unbalanced,
        "the branch is not closed before `;`",
        "la rama no se cierra antes del `;`",
    ),
    (
        Code::UnterminatedRung,
        "the last rung does not end with `;`",
        "el último peldaño no termina en `;`",
    ),
    (
        Code::UnterminatedRung,
        "a comment inside a rung: the rung before it does not end with `;`",
        "un comentario dentro de un peldaño: el peldaño anterior no termina en `;`",
    ),
    (
        Code::Syntax,
        "a comment inside a rung",
        "un comentario dentro de un peldaño",
    ),
    (Code::Syntax, "unexpected `{}`", "`{0}` inesperado"),
    (Code::Syntax, "unexpected {}", "{0} inesperado"),
    (
        Code::Syntax,
        "expected `(` after `{}`",
        "se esperaba `(` después de `{0}`",
    ),
    (Code::EmptyLeg, "empty branch leg", "tramo de rama vacío"),
    (
        Code::Unbalanced,
        "the `(` of `{}` is not closed",
        "el `(` de `{0}` no se cierra",
    ),
    (
        Code::Unbalanced,
        "`]` inside the operands of `{}`",
        "`]` dentro de los operandos de `{0}`",
    ),
    (Code::Syntax, "empty operand in `{}`", "operando vacío en `{0}`"),
    (
        Code::Syntax,
        "branches are nested more than {} deep",
        "las ramas se anidan a más de {0} niveles",
    ),
    (Code::CsvHeader, "tags.csv is empty", "tags.csv está vacío"),
    (
        Code::CsvHeader,
        "the header of tags.csv needs the columns `name` and `type`",
        "la cabecera de tags.csv necesita las columnas `name` y `type`",
    ),
    (Code::BadAddress, "`{}` is not an address", "`{0}` no es una dirección"),
    (
        Code::BadAddress,
        "`{}` is an SLC 500 timer or counter, a structure rather than an address",
        "`{0}` es un temporizador o contador del SLC 500, una estructura y no una dirección",
    ),
    (
        Code::DuplicateTag,
        "tag `{}` is declared twice",
        "la variable `{0}` está declarada dos veces",
    ),
    (Code::UnknownType, "unknown type {}", "tipo desconocido {0}"),
    (
        Code::CsvHeader,
        "unknown column `{}` in the header",
        "columna desconocida `{0}` en la cabecera",
    ),
    (
        Code::CsvHeader,
        "column `{}` appears twice in the header",
        "la columna `{0}` aparece dos veces en la cabecera",
    ),
    (
        Code::CsvSyntax,
        "this row has {} fields but the header has {}",
        "esta fila tiene {0} campos pero la cabecera tiene {1}",
    ),
    (
        Code::BadTagName,
        "`{}` reads as an address; choose another name",
        "`{0}` se lee como una dirección; elija otro nombre",
    ),
    (
        Code::TypeAddressMismatch,
        "a {} tag cannot be on {}",
        "una variable {0} no puede estar en {1}",
    ),
    (
        Code::BadInitialValue,
        "bad initial value for `{}`: {}",
        "valor inicial incorrecto para `{0}`: {1}",
    ),
    (
        Code::BadRetain,
        "`{}` is not a retain flag",
        "`{0}` no es un indicador de retención",
    ),
    (Code::Expression, "unknown function `{}`", "función desconocida `{0}`"),
    (
        Code::ConfigField,
        "unknown ladder dialect `{}`",
        "dialecto de Ladder desconocido `{0}`",
    ),
    (Code::ConfigField, "unknown board `{}`", "placa desconocida `{0}`"),
    (
        Code::ConfigField,
        "unknown pin map `{}`",
        "mapa de pines desconocido `{0}`",
    ),
    (
        Code::PlantModel,
        "unknown plant model kind `{}`",
        "tipo de modelo de planta desconocido `{0}`",
    ),
];

/// Labels and hints shared by many codes: (English pattern, Spanish).
pub const PHRASES: &[(&str, &str)] = &[
    ("here", "aquí"),
    ("did you mean `{}`?", "¿quiso decir `{0}`?"),
    ("not writable", "no se puede escribir"),
    ("rung without output", "peldaño sin salida"),
    ("input at the end", "entrada al final"),
    ("expected a name", "se esperaba un nombre"),
    ("expected a tag to write", "se esperaba una variable que escribir"),
    ("expected an integer", "se esperaba un entero"),
    ("not a number", "no es un número"),
    ("comment here", "comentario aquí"),
    ("expected `;` here", "se esperaba `;` aquí"),
    ("`[` without its `]`", "`[` sin su `]`"),
    ("expected `]` before this", "se esperaba `]` antes de esto"),
    (
        "expected an instruction, `[`, `,`, `]` or `;`",
        "se esperaba una instrucción, `[`, `,`, `]` o `;`",
    ),
    (
        "expected an instruction in this leg",
        "se esperaba una instrucción en este tramo",
    ),
    ("one branch too many", "una rama de más"),
    ("not an instruction", "no es una instrucción"),
    ("expected a header here", "se esperaba una cabecera aquí"),
    ("repeated column", "columna repetida"),
    ("not a tags.csv column", "no es una columna de tags.csv"),
    ("header", "cabecera"),
    ("extra field", "campo de más"),
    ("tag name", "nombre de variable"),
    ("second declaration", "segunda declaración"),
    ("expected a data type", "se esperaba un tipo de dato"),
    ("expected an address", "se esperaba una dirección"),
    ("bad address", "dirección incorrecta"),
    ("expected {}", "se esperaba {0}"),
    ("`{}` first declared here", "`{0}` declarada aquí por primera vez"),
    ("start the file with `{}`", "empiece el archivo con `{0}`"),
    ("the columns are {}", "las columnas son {0}"),
    ("this address holds {}", "esta dirección contiene {0}"),
];

/// Spanish explanations (`alba explain --lang es`) of the codes a student meets
/// first; the others are explained in English under their Spanish title.
pub const EXPLANATIONS: &[(Code, &str)] = &[
    (
        Code::Io,
        "Alba no pudo abrir, leer o escribir un archivo del proyecto. El mensaje nombra el archivo y el motivo que da el sistema operativo.",
    ),
    (
        Code::TomlSyntax,
        "alba.toml debe ser un documento TOML (https://toml.io). Revise comillas, corchetes y pares `clave = valor` cerca del lugar indicado.",
    ),
    (
        Code::CsvSyntax,
        "Los archivos CSV separan los campos con comas, ponen entre comillas dobles los campos que contienen comas o comillas (una comilla dentro se escribe dos veces) y tienen un registro por línea; cada registro tiene tantos campos como la cabecera.",
    ),
    (
        Code::CsvHeader,
        "tags.csv empieza con la cabecera `name,type,address,initial,retain,description` (las columnas distintas de name y type pueden omitirse). Un archivo de estímulos empieza con `time_ms,tag,value`.",
    ),
    (
        Code::BadTagName,
        "Los nombres de variable usan letras, dígitos y `_`, no empiezan por un dígito y no deben leerse como una dirección (como `MW2` o `I0.0`) ni ser una palabra reservada.",
    ),
    (
        Code::UnknownType,
        "Los tipos son BOOL, SINT, INT, DINT, LINT, REAL, LREAL, TIME, TIMER, COUNTER y PID (sin distinguir mayúsculas).",
    ),
    (
        Code::DuplicateTag,
        "Los nombres de variable no distinguen mayúsculas, como exige IEC 61131-3: `Motor` y `MOTOR` son la misma variable. Renombre o quite una de ellas.",
    ),
    (
        Code::AddressUsedTwice,
        "Cada canal de E/S o byte de marcas pertenece a una sola variable. Dos notaciones del mismo canal (DI:1/9 y %IX1.1) son la misma dirección; también lo son palabras de marcas que se solapan (MW0 y MD0).",
    ),
    (
        Code::BoardPin,
        "Con un `[board]` en alba.toml, cada canal de E/S que usa una variable debe estar cableado por el mapa de pines a un pin que la placa tiene y que puede servirlo: un pin digital para DI/DO (no D0/D1, el enlace serie), uno analógico para AI, uno PWM para AO. Use otro canal, otro mapa de pines u otra placa, o liste los pines en `[board]` (`di`, `do`, `ai`, `ao`).",
    ),
    (
        Code::Syntax,
        "Un peldaño es una secuencia de instrucciones `NOMBRE(operando,...)` y ramas `[tramo,tramo,...]`, terminada en `;`. Una línea de comentario `//` justo encima de un peldaño es su comentario.",
    ),
    (
        Code::Unbalanced,
        "Cada `[` de una rama necesita su `]` y cada `(` su `)` antes del `;` que termina el peldaño.",
    ),
    (
        Code::EmptyLeg,
        "Cada tramo de una rama `[a,b]` contiene al menos una instrucción.",
    ),
    (
        Code::UnterminatedRung,
        "Todo peldaño, también el último, termina en `;`.",
    ),
    (
        Code::UnknownTag,
        "Los operandos nombran variables de tags.csv (sin distinguir mayúsculas), sus miembros (`Delay.DN`), direcciones, variables del sistema (`S:FS`) o literales.",
    ),
    (
        Code::OperandCount,
        "Cada instrucción lleva un número fijo de operandos; el mensaje dice cuántos.",
    ),
    (
        Code::OperandType,
        "La instrucción necesita aquí otro tipo de operando: un BOOL para contactos y bobinas, un número para comparaciones y cálculo, una variable TIMER o COUNTER para temporizadores y contadores.",
    ),
    (
        Code::NotWritable,
        "Las entradas (DI, AI y las variables en ellas), los literales, las variables del sistema y los bits de estado de temporizadores y contadores (EN TT DN CU CD OV UN) son de solo lectura para los programas; RES pone a cero un temporizador o contador.",
    ),
    (
        Code::UnknownMember,
        "TIMER tiene PRE ACC EN TT DN; COUNTER tiene PRE ACC CU CD DN OV UN.",
    ),
    (
        Code::MissingLabel,
        "Un JMP nombra una etiqueta puesta con LBL(etiqueta) al principio de un peldaño del mismo programa.",
    ),
    (
        Code::NoOutput,
        "Todo peldaño necesita una instrucción de salida (OTE, OTL, un temporizador, un contador, una instrucción de cálculo o de movimiento, JMP, NOP...), y un peldaño o el último tramo de una rama debe terminar con una.",
    ),
    (
        Code::BadLiteral,
        "Los literales enteros son decimales o con base (16#FF), los reales llevan punto (1.5, 2.0e3), los tiempos son T#5s o T#1m30s; el valor debe caber donde va. La base de tiempo de un temporizador es ms, cs, ds, s o min (o 0.001, 0.01, 0.1, 1.0, 60 segundos).",
    ),
    (
        Code::StimulusSyntax,
        "Los archivos de estímulos tienen la cabecera `time_ms,tag,value`; time_ms es un entero no negativo; los valores son 0/1, true/false, enteros o reales.",
    ),
    (Code::BadArgument, "Vea `alba help <orden>` para los valores aceptados."),
];

/// The Spanish explanation of `code`, if the catalogue has it.
pub fn explanation(code: Code) -> Option<&'static str> {
    EXPLANATIONS.iter().find(|(c, _)| *c == code).map(|(_, t)| *t)
}

/// The noun phrases sites put into messages (what an operand is, what was
/// expected), in Spanish; a value not listed is kept, except `a X`/`an X` with X
/// a type name (`a BOOL` → `un BOOL`).
pub const VALUES: &[(&str, &str)] = &[
    ("a BOOL tag to write", "una variable BOOL que escribir"),
    ("a TIMER tag", "una variable TIMER"),
    ("a COUNTER tag", "una variable COUNTER"),
    ("a TIMER or COUNTER tag", "una variable TIMER o COUNTER"),
    (
        "an integer preset (literal, `?` or integer tag)",
        "una preselección entera (literal, `?` o variable entera)",
    ),
    ("an integer literal or `?`", "un literal entero o `?`"),
    ("a number (tag or literal)", "un número (variable o literal)"),
    ("a numeric tag to write", "una variable numérica que escribir"),
    ("a PID tag", "una variable PID"),
    ("something else", "otra cosa"),
    ("a boolean literal", "un literal booleano"),
    ("a REAL literal", "un literal REAL"),
    ("an integer literal", "un literal entero"),
    ("a number", "un número"),
    ("an integer", "un entero"),
];

/// A value of a message in Spanish ([`VALUES`]).
pub fn value(v: &str) -> String {
    if let Some((_, es)) = VALUES.iter().find(|(en, _)| *en == v) {
        return es.to_string();
    }
    let type_name = |t: &str| {
        !t.is_empty()
            && t.chars()
                .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_')
    };
    match v.strip_prefix("a ").or_else(|| v.strip_prefix("an ")) {
        Some(t) if type_name(t) => format!("un {t}"),
        _ => v.to_string(),
    }
}

fn fill_values(template: &str, values: &[&str]) -> String {
    let values: Vec<String> = values.iter().map(|v| value(v)).collect();
    let refs: Vec<&str> = values.iter().map(String::as_str).collect();
    crate::lang::fill(template, &refs)
}

/// The Spanish title of `code`, if the catalogue has it.
pub fn title(code: Code) -> Option<&'static str> {
    TITLES.iter().find(|(c, _)| *c == code).map(|(_, t)| *t)
}

/// `message` of `code` in Spanish by its template, if one matches.
pub fn message(code: Code, message: &str) -> Option<String> {
    MESSAGES
        .iter()
        .filter(|(c, _, _)| *c == code)
        .find_map(|(_, en, es)| crate::lang::match_template(en, message).map(|v| fill_values(es, &v)))
}

/// A label or hint in Spanish, if the phrase book has it.
pub fn phrase(text: &str) -> Option<String> {
    PHRASES
        .iter()
        .find_map(|(en, es)| crate::lang::match_template(en, text).map(|v| fill_values(es, &v)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_code_has_its_spanish_title() {
        let missing: Vec<String> = Code::ALL
            .iter()
            .filter(|c| title(**c).is_none_or(|t| t.trim().is_empty()))
            .map(|c| format!("{c} ({})", c.title()))
            .collect();
        assert!(missing.is_empty(), "codes without a Spanish title: {missing:?}");
        assert_eq!(TITLES.len(), Code::ALL.len(), "a code is listed twice");
        for (c, es) in TITLES {
            assert_ne!(*es, c.title(), "{c}: the Spanish title is the English one");
        }
    }

    #[test]
    fn the_codes_a_student_meets_first_are_explained_in_spanish() {
        for c in [
            Code::UnknownTag,
            Code::Syntax,
            Code::Unbalanced,
            Code::UnterminatedRung,
            Code::OperandCount,
            Code::OperandType,
            Code::NoOutput,
            Code::CsvHeader,
            Code::UnknownType,
            Code::DuplicateTag,
        ] {
            assert!(
                explanation(c).is_some_and(|e| !e.trim().is_empty()),
                "{c} lacks its Spanish explanation"
            );
        }
        let mut seen = std::collections::HashSet::new();
        for (c, e) in EXPLANATIONS {
            assert!(seen.insert(*c), "{c} explained twice");
            assert_ne!(*e, c.explanation(), "{c}: the Spanish explanation is the English one");
        }
    }

    #[test]
    fn templates_keep_their_placeholders() {
        for (c, en, es) in MESSAGES {
            let n = en.matches("{}").count();
            for i in 0..n {
                assert!(es.contains(&format!("{{{i}}}")), "{c} `{es}` lacks {{{i}}}");
            }
            assert!(!es.contains(&format!("{{{n}}}")), "{c} `{es}` has a value too many");
        }
        for (en, es) in PHRASES {
            let n = en.matches("{}").count();
            for i in 0..n {
                assert!(es.contains(&format!("{{{i}}}")), "`{es}` lacks {{{i}}}");
            }
        }
    }

    #[test]
    fn messages_translate_with_their_values() {
        assert_eq!(
            message(Code::UnknownTag, "unknown tag `Strat`").as_deref(),
            Some("variable desconocida `Strat`")
        );
        assert_eq!(
            message(
                Code::OperandCount,
                "TON takes 3 operands, or 4 with a time base, found 2"
            )
            .as_deref(),
            Some("TON lleva 3 operandos, o 4 con base de tiempo; hay 2")
        );
        // A template belongs to its code.
        assert_eq!(message(Code::Syntax, "unknown tag `Strat`"), None);
        assert_eq!(
            phrase("did you mean `Start`?").as_deref(),
            Some("¿quiso decir `Start`?")
        );
    }
}
