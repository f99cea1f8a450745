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
    (
        Code::AddressUsedTwice,
        "address {} is already used by `{}` ({})",
        "la dirección {0} ya la usa `{1}` ({2})",
    ),
    (
        Code::AlarmFile,
        "`{}` is a BOOL: compare numbers, or use on, off, rising or falling",
        "`{0}` es un BOOL: compare números, o use on, off, rising o falling",
    ),
    (
        Code::AlarmFile,
        "`{}` is a structure; name a member (`{}.DN`, `{}.ACC`)",
        "`{0}` es una estructura; nombre un miembro (`{1}.DN`, `{2}.ACC`)",
    ),
    (
        Code::AlarmFile,
        "`{}` is not a deadband: write a number ≥ 0",
        "`{0}` no es una banda muerta: escriba un número ≥ 0",
    ),
    (
        Code::AlarmFile,
        "`{}` is not an alarm id",
        "`{0}` no es un id de alarma",
    ),
    (
        Code::AlarmFile,
        "`{}` is not an on-delay: write 0 to {} milliseconds",
        "`{0}` no es un retardo a la conexión: escriba de 0 a {1} milisegundos",
    ),
    (Code::AlarmFile, "alarms.csv is empty", "alarms.csv está vacío"),
    (Code::AlarmFile, "cannot read {}: {}", "no se puede leer {0}: {1}"),
    (
        Code::AlarmFile,
        "the alarm id `{}` is used twice",
        "el id de alarma `{0}` se usa dos veces",
    ),
    (
        Code::AlarmFile,
        "the header of alarms.csv must be `{}`",
        "la cabecera de alarms.csv debe ser `{0}`",
    ),
    (Code::AlarmFile, "{} is larger than {} MiB", "{0} ocupa más de {1} MiB"),
    (
        Code::BadAddress,
        "R {}, {} runs past the last number 255",
        "R {0}, {1} pasa del último número, 255",
    ),
    (
        Code::BadAddress,
        "{} {}, {} runs past the end of {}",
        "{0} {1}, {2} pasa del final de {3}",
    ),
    (
        Code::BadArgument,
        "--every {} is not a positive multiple of the scan period ({} ms)",
        "--every {0} no es un múltiplo positivo del periodo de ciclo ({1} ms)",
    ),
    (Code::BadArgument, "--summary: {}", "--summary: {0}"),
    (Code::BadLiteral, "`{}` does not fit {}", "`{0}` no cabe en {1}"),
    (
        Code::BadLiteral,
        "`{}` does not fit {} `{}` ({} to {})",
        "`{0}` no cabe en {1} `{2}` ({3} a {4})",
    ),
    (
        Code::BadLiteral,
        "`{}` is beyond the REAL range, and this expression is computed in REAL",
        "`{0}` está fuera del rango REAL, y esta expresión se calcula en REAL",
    ),
    (
        Code::BadLiteral,
        "`{}` is not a preset of T{}, which counts {} ms from 0 to 32767 times",
        "`{0}` no es una preselección de T{1}, que cuenta {2} ms de 0 a 32767 veces",
    ),
    (
        Code::BadLiteral,
        "`{}` is not a time base; write ms, cs, ds, s or min (or 0.001, 0.01, 0.1, 1.0, 60 seconds)",
        "`{0}` no es una base de tiempo; escriba ms, cs, ds, s o min (o 0.001, 0.01, 0.1, 1.0, 60 segundos)",
    ),
    (
        Code::BadLiteral,
        "`{}` is not a whole number of {} (the timer's time base)",
        "`{0}` no es un número entero de {1} (la base de tiempo del temporizador)",
    ),
    (
        Code::BadLiteral,
        "`{}` must be a constant from {} to {}",
        "`{0}` debe ser una constante de {1} a {2}",
    ),
    (
        Code::BadLiteral,
        "a timer preset cannot be negative",
        "la preselección de un temporizador no puede ser negativa",
    ),
    (
        Code::BadLiteral,
        "a timer preset or accumulator cannot be negative",
        "la preselección o el acumulado de un temporizador no puede ser negativo",
    ),
    (Code::BadLiteral, "{} does not fit a DINT", "{0} no cabe en un DINT"),
    (
        Code::ConfigField,
        "[domain] `{}` is a structure, not an input",
        "[domain] `{0}` es una estructura, no una entrada",
    ),
    (
        Code::ConfigField,
        "[domain] `{}` is an output, driven by the program, not an input",
        "[domain] `{0}` es una salida, que escribe el programa, no una entrada",
    ),
    (
        Code::ConfigField,
        "[domain] `{}` lists no value",
        "[domain] `{0}` no da ningún valor",
    ),
    (
        Code::ConfigField,
        "[domain] `{}`: bad value {}: {}",
        "[domain] `{0}`: valor incorrecto {1}: {2}",
    ),
    (
        Code::ConfigField,
        "`[http]` needs both `cert` and `key`, or neither",
        "`[http]` necesita `cert` y `key` a la vez, o ninguno de los dos",
    ),
    (
        Code::ConfigField,
        "`baud` is a setting of serial (rtu) devices",
        "`baud` es un ajuste de los dispositivos serie (rtu)",
    ),
    (Code::ConfigField, "`port` is empty", "`port` está vacío"),
    (Code::ConfigField, "`programs` is empty", "`programs` está vacío"),
    (
        Code::ConfigField,
        "`{}` is not a host name",
        "`{0}` no es un nombre de host",
    ),
    (
        Code::ConfigField,
        "`{}` is not a pin name",
        "`{0}` no es un nombre de pin",
    ),
    (
        Code::ConfigField,
        "`{}` is not a user name",
        "`{0}` no es un nombre de usuario",
    ),
    (Code::ConfigField, "`{}` is not an origin", "`{0}` no es un origen"),
    (
        Code::ConfigField,
        "`{}` is not in [opcua.users]",
        "`{0}` no está en [opcua.users]",
    ),
    (
        Code::ConfigField,
        "a property needs a non-empty `name`",
        "una propiedad necesita un `name` no vacío",
    ),
    (
        Code::ConfigField,
        "backend = \"postgres\" needs a url",
        "backend = \"postgres\" necesita una url",
    ),
    (
        Code::ConfigField,
        "client_cert and client_key go together",
        "client_cert y client_key van juntos",
    ),
    (
        Code::ConfigField,
        "client_cert without ca_file",
        "client_cert sin ca_file",
    ),
    (
        Code::ConfigField,
        "deadband = {} is out of range",
        "deadband = {0} está fuera de rango",
    ),
    (
        Code::ConfigField,
        "device `{}` needs exactly one of `tcp` and `rtu`",
        "el dispositivo `{0}` necesita exactamente uno de `tcp` y `rtu`",
    ),
    (
        Code::ConfigField,
        "listen = \"{}\" is not a loopback address, so it needs users",
        "listen = \"{0}\" no es una dirección de loopback, así que necesita usuarios",
    ),
    (
        Code::ConfigField,
        "listen = \"{}\" is not an address and port",
        "listen = \"{0}\" no es una dirección y un puerto",
    ),
    (Code::ConfigField, "node is empty", "node está vacío"),
    (
        Code::ConfigField,
        "pin {} is not a digital output of this board's pin map",
        "el pin {0} no es una salida digital del mapa de pines de esta placa",
    ),
    (
        Code::ConfigField,
        "pin {} is wired to two channels",
        "el pin {0} está cableado a dos canales",
    ),
    (
        Code::ConfigField,
        "pin {} is wired twice",
        "el pin {0} está cableado dos veces",
    ),
    (
        Code::ConfigField,
        "property `{}` has {} kinds; it needs exactly one",
        "la propiedad `{0}` tiene {1} clases; necesita exactamente una",
    ),
    (
        Code::ConfigField,
        "property `{}`: a mutex lists at least two expressions",
        "propiedad `{0}`: un mutex lista al menos dos expresiones",
    ),
    (
        Code::ConfigField,
        "tcp = \"{}\" is not a host and port",
        "tcp = \"{0}\" no es un host y un puerto",
    ),
    (
        Code::ConfigField,
        "the project name is empty",
        "el nombre del proyecto está vacío",
    ),
    (
        Code::ConfigField,
        "two properties are named `{}`",
        "dos propiedades se llaman `{0}`",
    ),
    (Code::ConfigField, "url holds a password", "url contiene una contraseña"),
    (
        Code::ConfigField,
        "version = {} is not an MQTT version Alba speaks",
        "version = {0} no es una versión de MQTT que Alba hable",
    ),
    (
        Code::ConfigField,
        "{} = {} is out of range",
        "{0} = {1} está fuera de rango",
    ),
    (
        Code::ConflictingPreset,
        "`{}` conflicts with the value {} given earlier for the same structure",
        "`{0}` choca con el valor {1} dado antes para la misma estructura",
    ),
    (
        Code::ConflictingPreset,
        "`{}` conflicts with the value {} given earlier to {}{}",
        "`{0}` choca con el valor {1} dado antes a {2}{3}",
    ),
    (
        Code::ConflictingPreset,
        "{} conflicts with the time base {} given earlier for the same timer",
        "{0} choca con la base de tiempo {1} dada antes para el mismo temporizador",
    ),
    (
        Code::CsvHeader,
        "a test table's first column is `time_ms`",
        "la primera columna de una tabla de prueba es `time_ms`",
    ),
    (
        Code::CsvHeader,
        "the stimulus file is empty",
        "el archivo de estímulos está vacío",
    ),
    (
        Code::CsvHeader,
        "the stimulus header must be `time_ms,tag,value`",
        "la cabecera de estímulos debe ser `time_ms,tag,value`",
    ),
    (
        Code::CsvHeader,
        "the test table is empty",
        "la tabla de prueba está vacía",
    ),
    (
        Code::DoesNotFit,
        "the firmware needs {} bytes of flash and {} bytes of RAM plus {} for the stack; the {} has {} and {}",
        "el firmware necesita {0} bytes de flash y {1} bytes de RAM más {2} para la pila; la {3} tiene {4} y {5}",
    ),
    (
        Code::DuplicateLabel,
        "LBL {} is set twice",
        "LBL {0} está puesta dos veces",
    ),
    (
        Code::DuplicateLabel,
        "label `{}` is set twice",
        "la etiqueta `{0}` está puesta dos veces",
    ),
    (
        Code::Expression,
        "booleans are not values in CPT; use 1 or 0",
        "los booleanos no son valores en CPT; use 1 o 0",
    ),
    (
        Code::Expression,
        "{} works on integers, but this expression is computed in {}",
        "{0} trabaja con enteros, pero esta expresión se calcula en {1}",
    ),
    (
        Code::IlNotSupported,
        "byte compares (LDB…) are not supported yet",
        "las comparaciones de bytes (LDB…) aún no están disponibles",
    ),
    (
        Code::IlNotSupported,
        "byte increments (INCB, DECB) are not supported yet",
        "los incrementos de bytes (INCB, DECB) aún no están disponibles",
    ),
    (
        Code::IlNotSupported,
        "local variables are not supported yet",
        "las variables locales aún no están disponibles",
    ),
    (
        Code::IlNotSupported,
        "subroutines and interrupt routines are not supported yet",
        "las subrutinas y rutinas de interrupción aún no están disponibles",
    ),
    (
        Code::IlSyntax,
        "`{}` is not one operand: operands are separated by commas",
        "`{0}` no es un solo operando: los operandos se separan con comas",
    ),
    (
        Code::IlSyntax,
        "a quoted symbol is not closed",
        "un símbolo entre comillas no se cierra",
    ),
    (Code::IlSyntax, "empty operand in `{}`", "operando vacío en `{0}`"),
    (
        Code::IlSyntax,
        "this `/*` comment is never closed",
        "este comentario `/*` nunca se cierra",
    ),
    (Code::Io, "cannot read {}: {}", "no se puede leer {0}: {1}"),
    (Code::Io, "cannot write {}: {}", "no se puede escribir {0}: {1}"),
    (
        Code::LabelNotFirst,
        "LBL must be the first instruction of its rung",
        "LBL debe ser la primera instrucción de su peldaño",
    ),
    (
        Code::LogicStack,
        "{} reaches {} values down the logic stack, but more than {} values were loaded since: the oldest fell off its bottom",
        "{0} alcanza {1} valores hacia abajo en la pila lógica, pero desde entonces se cargaron más de {2} valores: el más antiguo cayó por el fondo",
    ),
    (
        Code::LoopStructure,
        "FOR loops nest at most {} deep",
        "los bucles FOR se anidan como mucho a {0} niveles",
    ),
    (Code::LoopStructure, "NEXT without its FOR", "NEXT sin su FOR"),
    (Code::LoopStructure, "this FOR has no NEXT", "este FOR no tiene NEXT"),
    (
        Code::MissingLabel,
        "no LBL {} in this program",
        "no hay LBL {0} en este programa",
    ),
    (
        Code::MissingLabel,
        "no rung has LBL({})",
        "ningún peldaño tiene LBL({0})",
    ),
    (
        Code::ModbusClients,
        "allow = [] lets no client in",
        "allow = [] no deja entrar a ningún cliente",
    ),
    (
        Code::ModbusClients,
        "listen = \"{}\" is not a loopback address, so it needs `allow`",
        "listen = \"{0}\" no es una dirección de loopback, así que necesita `allow`",
    ),
    (
        Code::ModbusTag,
        "`{}` ({}) overlaps `{}` ({})",
        "`{0}` ({1}) se solapa con `{2}` ({3})",
    ),
    (
        Code::ModbusTag,
        "`{}` is a {}: it goes on {}",
        "`{0}` es un {1}: va en {2}",
    ),
    (
        Code::ModbusTag,
        "`{}` is {}: clients write {}, so put it on {}",
        "`{0}` es {1}: los clientes escriben {2}, así que póngalo en {3}",
    ),
    (
        Code::ModbusTag,
        "`{}` needs {} registers: {} runs past 65535",
        "`{0}` necesita {1} registros: {2} pasa de 65535",
    ),
    (
        Code::NetArc,
        "an inhibitor or read arc goes from a place to a transition",
        "un arco inhibidor o de lectura va de un lugar a una transición",
    ),
    (
        Code::NetGuard,
        "the guard of transition `{}` is a number, not a BOOL",
        "la guarda de la transición `{0}` es un número, no un BOOL",
    ),
    (
        Code::NetMode,
        "{} {} element runs in normal mode, not in a Petri-mode net",
        "{0} elemento {1} se ejecuta en modo normal, no en una red en modo Petri",
    ),
    (
        Code::NetRange,
        "the arcs between these two nodes weigh more than a DINT holds",
        "los arcos entre estos dos nodos pesan más de lo que cabe en un DINT",
    ),
    (
        Code::NetRange,
        "the initial marking {} does not fit a DINT",
        "el marcado inicial {0} no cabe en un DINT",
    ),
    (
        Code::NetRange,
        "the weight {} does not fit a DINT marking",
        "el peso {0} no cabe en un marcado DINT",
    ),
    (
        Code::NetScript,
        "expression `{}` has no `<script>`",
        "la expresión `{0}` no tiene `<script>`",
    ),
    (
        Code::NetScript,
        "script of `{}`, line {} col {}: {}",
        "guion de `{0}`, línea {1} col {2}: {3}",
    ),
    (
        Code::NetTagClash,
        "the marking of place `{}` is the tag `{}`, which already exists",
        "el marcado del lugar `{0}` es la variable `{1}`, que ya existe",
    ),
    (
        Code::NetTagClash,
        "the marking of place `{}` would be `{}`, a member of the {} `{}`",
        "el marcado del lugar `{0}` sería `{1}`, un miembro de {2} `{3}`",
    ),
    (
        Code::NetTagClash,
        "the step flag `{}` is already a tag",
        "la marca de etapa `{0}` ya es una variable",
    ),
    (
        Code::NetTagClash,
        "{} is the tag `{}`, which already exists",
        "{0} es la variable `{1}`, que ya existe",
    ),
    (
        Code::NotOnBoard,
        "`{}` is a LINT: the byte-code interpreter on the {} holds no 64-bit integers (the Mega's does, and so does the compiled sketch)",
        "`{0}` es un LINT: el intérprete de código de bytes de la {1} no tiene enteros de 64 bits (el de la Mega sí, y también el sketch compilado)",
    ),
    (
        Code::NotOnBoard,
        "`{}` is an LREAL, which the {} cannot hold: avr-gcc's double has 32 bits",
        "`{0}` es un LREAL, que la {1} no puede guardar: el double de avr-gcc tiene 32 bits",
    ),
    (
        Code::NotOnBoard,
        "not downloaded to {}: {}",
        "no se descargó en {0}: {1}",
    ),
    (
        Code::NotOnBoard,
        "the byte code is {} bytes; the interpreter on the {} holds {} (half its EEPROM: a download never overwrites the running program): use the Mega, or the compiled sketch (alba export arduino)",
        "el código de bytes ocupa {0} bytes; el intérprete de la {1} admite {2} (la mitad de su EEPROM: una descarga nunca sobrescribe el programa en marcha): use la Mega, o el sketch compilado (alba export arduino)",
    ),
    (
        Code::NotOnBoard,
        "the interpreter on the {} cannot run this program: {}",
        "el intérprete de la {0} no puede ejecutar este programa: {1}",
    ),
    (
        Code::NotWritable,
        "S cannot set `{}`: timers and counters are set by their instructions",
        "S no puede activar `{0}`: los temporizadores y contadores los activan sus instrucciones",
    ),
    (
        Code::NotWritable,
        "`{}` cannot be written",
        "`{0}` no se puede escribir",
    ),
    (
        Code::NotWritable,
        "`{}` cannot be written, so it is no VAR_IN_OUT argument",
        "`{0}` no se puede escribir, así que no es un argumento VAR_IN_OUT",
    ),
    (
        Code::NotWritable,
        "`{}` is a constant and cannot be written",
        "`{0}` es una constante y no se puede escribir",
    ),
    (
        Code::NotWritable,
        "`{}` is a {} bit, set by its instruction",
        "`{0}` es un bit {1}, que activa su instrucción",
    ),
    (
        Code::OpcuaUsersDeprecated,
        "[opcua.users] is deprecated: users now live in users.toml, for every interface",
        "[opcua.users] está obsoleto: los usuarios viven ahora en users.toml, para todas las interfaces",
    ),
    (
        Code::OperandCount,
        "LBL takes one operand, the label number",
        "LBL lleva un operando, el número de etiqueta",
    ),
    (
        Code::OperandCount,
        "{} takes {} operand{}, found {}",
        "{0} lleva {1} operando{2}; hay {3}",
    ),
    (
        Code::OperandType,
        "CPT needs numbers, found {} `{}`",
        "CPT necesita números; hay {0} `{1}`",
    ),
    (
        Code::OperandType,
        "`{}` has no address, so it has no next bits for N = {}",
        "`{0}` no tiene dirección, así que no tiene bits siguientes para N = {1}",
    ),
    (
        Code::OperandType,
        "`{}` is a Logix TIMER or COUNTER tag; AWL uses S7 timers (T37) and counters (C5)",
        "`{0}` es una variable TIMER o COUNTER de Logix; AWL usa temporizadores (T37) y contadores (C5) del S7",
    ),
    (
        Code::OperandType,
        "`{}` is not a {}: {}s are {}0 to {}255",
        "`{0}` no es un {1}: los {2} van de {3}0 a {4}255",
    ),
    (
        Code::OperandType,
        "{} needs a bit, `{}` is {}",
        "{0} necesita un bit; `{1}` es {2}",
    ),
    (
        Code::OperandType,
        "{} needs {}, `{}` is a word",
        "{0} necesita {1}; `{2}` es una palabra",
    ),
    (
        Code::OperandType,
        "{} needs {}, `{}` is {}",
        "{0} necesita {1}; `{2}` es {3}",
    ),
    (
        Code::OperandType,
        "{} works on integers, but `{}` is {}",
        "{0} trabaja con enteros, pero `{1}` es {2}",
    ),
    (
        Code::PnmlAlba,
        "<{}> is not Alba data here",
        "<{0}> no es un dato de Alba aquí",
    ),
    (
        Code::PnmlAlba,
        "`{}` is not a kind of {}",
        "`{0}` no es una clase de {1}",
    ),
    (Code::PnmlAlba, "`{}` is not a mode", "`{0}` no es un modo"),
    (
        Code::PnmlAlba,
        "`{}` is not an arc kind",
        "`{0}` no es una clase de arco",
    ),
    (
        Code::PnmlAlba,
        "a <prop> needs a `name`",
        "un <prop> necesita un `name`",
    ),
    (
        Code::PnmlAlba,
        "a <widget> needs a `kind`: button, display, plot or label",
        "un <widget> necesita un `kind`: button, display, plot o label",
    ),
    (Code::PnmlAlba, "a second <{}>", "un segundo <{0}>"),
    (
        Code::PnmlAlba,
        "a second Alba <toolspecific> block on one element",
        "un segundo bloque <toolspecific> de Alba en un mismo elemento",
    ),
    (
        Code::PnmlAlba,
        "an arc type is normal, inhibitor or read",
        "un tipo de arco es normal, inhibitor o read",
    ),
    (Code::PnmlAlba, "an empty <guard>", "un <guard> vacío"),
    (Code::PnmlAlba, "an empty <tag>", "un <tag> vacío"),
    (
        Code::PnmlAlba,
        "arc `{}`: {} arcs go from a place to a transition",
        "arco `{0}`: los arcos {1} van de un lugar a una transición",
    ),
    (
        Code::PnmlAlba,
        "the property `{}` is given twice",
        "la propiedad `{0}` se da dos veces",
    ),
    (
        Code::PnmlArc,
        "a second arc from `{}` to `{}`",
        "un segundo arco de `{0}` a `{1}`",
    ),
    (
        Code::PnmlArc,
        "arc `{}` joins two {} (`{}` → `{}`)",
        "el arco `{0}` une dos {1} (`{2}` → `{3}`)",
    ),
    (
        Code::PnmlArc,
        "arc `{}`: its {} `{}` is not a place or transition of the net",
        "arco `{0}`: su {1} `{2}` no es un lugar ni una transición de la red",
    ),
    (
        Code::PnmlArc,
        "the reference `{}` refers to itself in a cycle",
        "la referencia `{0}` se refiere a sí misma en un ciclo",
    ),
    (
        Code::PnmlArc,
        "the reference node `{}` refers to `{}`, which is not in the document",
        "el nodo de referencia `{0}` se refiere a `{1}`, que no está en el documento",
    ),
    (
        Code::PnmlDuplicateId,
        "the id `{}` is used twice",
        "el id `{0}` se usa dos veces",
    ),
    (
        Code::PnmlIgnored,
        "<{}> in <{}> is not part of a place/transition net: ignored",
        "<{0}> en <{1}> no forma parte de una red lugar/transición: se ignora",
    ),
    (
        Code::PnmlIgnored,
        "Alba <toolspecific> version `{}` is not version 1: kept unread",
        "la versión `{0}` de <toolspecific> de Alba no es la versión 1: se conserva sin leer",
    ),
    (
        Code::PnmlIgnored,
        "net type `{}` is not a place/transition net: read as one",
        "el tipo de red `{0}` no es una red lugar/transición: se lee como una",
    ),
    (
        Code::PnmlIgnored,
        "the <{}> of a nested page is dropped: pages are flattened into the first",
        "se descarta el <{0}> de una página anidada: las páginas se aplanan en la primera",
    ),
    (
        Code::PnmlLimit,
        "the file has {} bytes; Alba reads PNML files up to {} MiB",
        "el archivo tiene {0} bytes; Alba lee archivos PNML de hasta {1} MiB",
    ),
    (
        Code::PnmlNumber,
        "a <position> needs decimal `x` and `y`",
        "un <position> necesita `x` e `y` decimales",
    ),
    (
        Code::PnmlNumber,
        "a <widget> needs decimal `x` and `y`",
        "un <widget> necesita `x` e `y` decimales",
    ),
    (Code::PnmlNumber, "{} {} is above {}", "{0} {1} es mayor que {2}"),
    (Code::PnmlNumber, "{} {} is below {}", "{0} {1} es menor que {2}"),
    (Code::PnmlStructure, "<net> has no `type`", "<net> no tiene `type`"),
    (
        Code::PnmlStructure,
        "<{}> has an empty `id`",
        "<{0}> tiene un `id` vacío",
    ),
    (Code::PnmlStructure, "<{}> has no <text>", "<{0}> no tiene <text>"),
    (Code::PnmlStructure, "<{}> has no `id`", "<{0}> no tiene `id`"),
    (Code::PnmlStructure, "<{}> has no `ref`", "<{0}> no tiene `ref`"),
    (
        Code::PnmlStructure,
        "a second <net>: Alba reads one net per file",
        "un segundo <net>: Alba lee una red por archivo",
    ),
    (
        Code::PnmlStructure,
        "a second <{}> on one element",
        "un segundo <{0}> en un mismo elemento",
    ),
    (
        Code::PnmlStructure,
        "an <arc> needs `source` and `target`",
        "un <arc> necesita `source` y `target`",
    ),
    (
        Code::PnmlStructure,
        "the document has no <net>",
        "el documento no tiene <net>",
    ),
    (
        Code::PnmlStructure,
        "the root element is <{}>, not <pnml>",
        "el elemento raíz es <{0}>, no <pnml>",
    ),
    (
        Code::S7Timer,
        "C{} is used as a {} and as a {}",
        "C{0} se usa como {1} y como {2}",
    ),
    (
        Code::S7Timer,
        "T{} is used as a {} and as a {}",
        "T{0} se usa como {1} y como {2}",
    ),
    (
        Code::SfcAction,
        "`{}` is a structure; name a BOOL member",
        "`{0}` es una estructura; nombre un miembro BOOL",
    ),
    (Code::SfcAction, "action {}", "acción {0}"),
    (
        Code::SfcAction,
        "the action `{}` cannot be driven: {}",
        "la acción `{0}` no se puede escribir: {1}",
    ),
    (
        Code::StName,
        "`{}` is VAR_EXTERNAL but no tag or VAR_GLOBAL has that name",
        "`{0}` es VAR_EXTERNAL pero ninguna variable ni VAR_GLOBAL tiene ese nombre",
    ),
    (
        Code::StName,
        "the enumeration {} has no value `{}`",
        "la enumeración {0} no tiene el valor `{1}`",
    ),
    (Code::StName, "unknown function `{}`", "función desconocida `{0}`"),
    (Code::StName, "unknown type `{}`", "tipo desconocido `{0}`"),
    (Code::StName, "unknown {} `{}`", "{0} desconocido `{1}`"),
    (Code::StName, "{} has no input `{}`", "{0} no tiene la entrada `{1}`"),
    (
        Code::StName,
        "{} has no input or output `{}`",
        "{0} no tiene la entrada o salida `{1}`",
    ),
    (Code::StName, "{} has no member `{}`", "{0} no tiene el miembro `{1}`"),
    (Code::StName, "{} has no output `{}`", "{0} no tiene la salida `{1}`"),
    (
        Code::StName,
        "{} has no variable `{}` to initialise",
        "{0} no tiene la variable `{1}` que inicializar",
    ),
    (Code::StName, "{} has no {} `{}`", "{0} no tiene {1} `{2}`"),
    (
        Code::StNotSupported,
        "`{}` calls itself ({}): calls are inlined, so recursion is not supported",
        "`{0}` se llama a sí misma ({1}): las llamadas se expanden en línea, así que no se admite la recursión",
    ),
    (Code::StSyntax, "expected {}, found {}", "se esperaba {0}; hay {1}"),
    (
        Code::StimulusSyntax,
        "`{}` is not a time in milliseconds",
        "`{0}` no es un tiempo en milisegundos",
    ),
    (
        Code::StimulusSyntax,
        "a stimulus row has 3 fields, this one has {}",
        "una fila de estímulos tiene 3 campos; esta tiene {0}",
    ),
    (
        Code::StimulusSyntax,
        "bad value `{}`: {}",
        "valor incorrecto `{0}`: {1}",
    ),
    (
        Code::StimulusSyntax,
        "bad value for `{}`: {}",
        "valor incorrecto para `{0}`: {1}",
    ),
    (
        Code::StimulusSyntax,
        "the rows of a test table go forward in time",
        "las filas de una tabla de prueba avanzan en el tiempo",
    ),
    (
        Code::StimulusSyntax,
        "this row has {} fields, the header {}",
        "esta fila tiene {0} campos, la cabecera {1}",
    ),
    (
        Code::StimulusTarget,
        "`{}` is a structure; name a member such as {}.DN",
        "`{0}` es una estructura; nombre un miembro como {1}.DN",
    ),
    (
        Code::StimulusTarget,
        "`{}` is a structure; set a member like {}.PRE",
        "`{0}` es una estructura; fije un miembro como {1}.PRE",
    ),
    (
        Code::StimulusTarget,
        "`{}` is an output, driven by the program",
        "`{0}` es una salida, que escribe el programa",
    ),
    (
        Code::StimulusTarget,
        "`{}` is read-only and cannot be set by a stimulus",
        "`{0}` es de solo lectura y un estímulo no puede fijarla",
    ),
    (
        Code::StimulusTarget,
        "`{}` is read-only and cannot be set by a test",
        "`{0}` es de solo lectura y una prueba no puede fijarla",
    ),
    (
        Code::StimulusTarget,
        "the stimulus forces a value at {} ms: forces are not available on the board's firmware (--firmware); write the value instead",
        "el estímulo fuerza un valor a los {0} ms: el firmware de la placa no admite forzados (--firmware); escriba el valor en su lugar",
    ),
    (
        Code::StimulusTarget,
        "the stimulus sets {} at {} ms on something that is not an input wired to a pin; firmware runs take only DI and AI inputs",
        "el estímulo fija {0} a los {1} ms en algo que no es una entrada cableada a un pin; las ejecuciones en firmware solo aceptan entradas DI y AI",
    ),
    (
        Code::StimulusTarget,
        "{} reads {} at {} ms, but an analog input of the board reads 0 to 1023",
        "{0} lee {1} a los {2} ms, pero una entrada analógica de la placa lee de 0 a 1023",
    ),
    (
        Code::Syntax,
        "`{}` is not a label name",
        "`{0}` no es un nombre de etiqueta",
    ),
    (
        Code::TraceName,
        "--tags has an empty name (two commas, or a comma at an end)",
        "--tags tiene un nombre vacío (dos comas, o una coma en un extremo)",
    ),
    (
        Code::TraceName,
        "--tags: `{}` is a structure; name a member such as {}.ACC or {}.DN",
        "--tags: `{0}` es una estructura; nombre un miembro como {1}.ACC o {2}.DN",
    ),
    (Code::TraceName, "--tags: {}", "--tags: {0}"),
    (
        Code::TraceName,
        "`{}` is an LREAL, which the board has not",
        "`{0}` es un LREAL, que la placa no tiene",
    ),
    (
        Code::Unbalanced,
        "branches are nested more than {} deep",
        "las ramas se anidan a más de {0} niveles",
    ),
    (Code::Unbalanced, "unexpected {}", "{0} inesperado"),
    (Code::UnknownTag, "[domain]: {}", "[domain]: {0}"),
    (
        Code::UsersFile,
        "`{}` is not a valid user name",
        "`{0}` no es un nombre de usuario válido",
    ),
    (Code::UsersFile, "users.toml: {}", "users.toml: {0}"),
    (
        Code::UsersFile,
        "{} can be read or written by other users (mode {}): its password hashes are for its owner only",
        "{0} pueden leerlo o escribirlo otros usuarios (modo {1}): sus hashes de contraseña son solo para su dueño",
    ),
    (Code::PnmlSyntax, "not well-formed XML: {}", "XML mal formado: {0}"),
    (
        Code::PnmlLimit,
        "the file is too large to read: {}",
        "el archivo es demasiado grande para leerlo: {0}",
    ),
    (
        Code::BadArgument,
        "--board {}: the boards are uno, nano and mega",
        "--board {0}: las placas son uno, nano y mega",
    ),
    (
        Code::BadArgument,
        "--pinmap {}: the presets are {}",
        "--pinmap {0}: los mapas predefinidos son {1}",
    ),
    (
        Code::BadArgument,
        "--pinmap: the presets are {}",
        "--pinmap: los mapas predefinidos son {0}",
    ),
    (
        Code::BadArgument,
        "no board: give --board uno|nano|mega or a [board] section in alba.toml",
        "no hay placa: dé --board uno|nano|mega o una sección [board] en alba.toml",
    ),
    (
        Code::BadArgument,
        "the aurora preset is missing",
        "falta el mapa predefinido aurora",
    ),
    (
        Code::BadArgument,
        "give --board uno|nano|mega, or a project with a [board] section",
        "dé --board uno|nano|mega, o un proyecto con una sección [board]",
    ),
    (
        Code::BadArgument,
        "unknown board `{}` (uno, nano or mega)",
        "placa desconocida `{0}` (uno, nano o mega)",
    ),
    (
        Code::BadArgument,
        "unknown link `{}` (modbus or aurora)",
        "enlace desconocido `{0}` (modbus o aurora)",
    ),
    (
        Code::BadArgument,
        "unknown pin map `{}` (aurora, s7 or openplc)",
        "mapa de pines desconocido `{0}` (aurora, s7 u openplc)",
    ),
    (
        Code::BadArgument,
        "which board? give --board uno|nano|mega, or a project with [board]",
        "¿qué placa? dé --board uno|nano|mega, o un proyecto con [board]",
    ),
    (
        Code::BadArgument,
        "{} has no [board] in alba.toml: add one or give --board (and --pinmap)",
        "{0} no tiene [board] en alba.toml: añada una o dé --board (y --pinmap)",
    ),
    (
        Code::NetElement,
        "`{}` is a structure; name a member",
        "`{0}` es una estructura; nombre un miembro",
    ),
    (
        Code::NetElement,
        "`{}` is not a variable mode",
        "`{0}` no es un modo de Variable",
    ),
    (
        Code::NetElement,
        "a counter counts `up` or `down`, not `{}`",
        "un contador cuenta `up` o `down`, no `{0}`",
    ),
    (
        Code::NetElement,
        "a normal-mode arc passes one token; this one weighs {}",
        "un arco en modo normal pasa una marca; este pesa {0}",
    ),
    (
        Code::NetElement,
        "a {} element has no property `{}`",
        "un elemento {0} no tiene la propiedad `{1}`",
    ),
    (
        Code::NetElement,
        "a {} element needs `{}`",
        "un elemento {0} necesita `{1}`",
    ),
    (
        Code::NetElement,
        "an output element needs `source` (a tag or a number)",
        "un elemento Output necesita `source` (una variable o un número)",
    ),
    (
        Code::NetElement,
        "condition `{}` needs a `<guard>`",
        "la condición `{0}` necesita una `<guard>`",
    ),
    (
        Code::NetElement,
        "inhibitor and read arcs are Petri mode's: a normal-mode token just flows",
        "los arcos inhibidores y de lectura son del modo Petri: en modo normal la marca solo fluye",
    ),
    (
        Code::NetElement,
        "the counter's load `{}` is not a DINT",
        "la carga `{0}` del contador no es un DINT",
    ),
    (
        Code::NetElement,
        "timer `{}` needs a delay",
        "el temporizador `{0}` necesita un retardo",
    ),
    (
        Code::NetGuard,
        "FRD and TOD are CPT's (BCD) functions, not a net's",
        "FRD y TOD son funciones (BCD) de CPT, no de una red",
    ),
    (
        Code::NetGuard,
        "NOT needs a BOOL in a guard, found a number",
        "NOT necesita un BOOL en una guarda; hay un número",
    ),
    (
        Code::NetGuard,
        "`-` needs a number, found a BOOL",
        "`-` necesita un número; hay un BOOL",
    ),
    (
        Code::NetGuard,
        "`{}` is a structure; name a member (`{}.DN`)",
        "`{0}` es una estructura; nombre un miembro (`{1}.DN`)",
    ),
    (
        Code::NetGuard,
        "a function needs numbers, found a BOOL",
        "una función necesita números; hay un BOOL",
    ),
    (
        Code::NetGuard,
        "this operation needs numbers on both sides, found a BOOL",
        "esta operación necesita números a ambos lados; hay un BOOL",
    ),
    (
        Code::NetGuard,
        "{} joins BOOLs in a guard; compare numbers first",
        "{0} une BOOL en una guarda; compare antes los números",
    ),
    (Code::SfcSyntax, "`{}` is not a priority", "`{0}` no es una prioridad"),
    (
        Code::SfcSyntax,
        "`{}` is not a qualifier: N S R L D P P1 P0 SD DS SL",
        "`{0}` no es un calificador: N S R L D P P1 P0 SD DS SL",
    ),
    (
        Code::SfcSyntax,
        "`{}` is not a step name",
        "`{0}` no es un nombre de etapa",
    ),
    (
        Code::SfcSyntax,
        "`{}` is not a time: write T#5s, T#250ms or milliseconds",
        "`{0}` no es un tiempo: escriba T#5s, T#250ms o milisegundos",
    ),
    (
        Code::SfcSyntax,
        "a `(*` comment is not closed",
        "un comentario `(*` no se cierra",
    ),
    (
        Code::SfcSyntax,
        "an SFC file is at most {} MiB",
        "un archivo SFC ocupa como mucho {0} MiB",
    ),
    (
        Code::SfcSyntax,
        "expected INITIAL_STEP, STEP or TRANSITION, found `{}`",
        "se esperaba INITIAL_STEP, STEP o TRANSITION; hay `{0}`",
    ),
    (
        Code::SfcSyntax,
        "expected `,` or `)` in a list of steps",
        "se esperaba `,` o `)` en una lista de etapas",
    ),
    (Code::SfcSyntax, "expected `,` or `)`", "se esperaba `,` o `)`"),
    (
        Code::SfcSyntax,
        "expected `:=` after PRIORITY",
        "se esperaba `:=` después de PRIORITY",
    ),
    (
        Code::SfcSyntax,
        "expected `:=` and the condition",
        "se esperaba `:=` y la condición",
    ),
    (
        Code::SfcSyntax,
        "expected `{}`, found the end of the file",
        "se esperaba `{0}`; el archivo se acaba",
    ),
    (
        Code::SfcSyntax,
        "expected {}, found the end of the file",
        "se esperaba {0}; el archivo se acaba",
    ),
    (Code::SfcSyntax, "expected {}", "se esperaba {0}"),
    (Code::SfcSyntax, "the condition is empty", "la condición está vacía"),
    (
        Code::SfcSyntax,
        "the condition is not ended by `;`",
        "la condición no termina en `;`",
    ),
    (
        Code::AlarmFile,
        "`{}` is an edge (an instant): it takes no on-delay",
        "`{0}` es un flanco (un instante): no lleva retardo a la conexión",
    ),
    (Code::AlarmFile, "`{}` is not a BOOL", "`{0}` no es un BOOL"),
    (
        Code::AlarmFile,
        "a deadband applies to comparisons, not to `{}`",
        "una banda muerta se aplica a comparaciones, no a `{0}`",
    ),
    (
        Code::AlarmFile,
        "an alarm needs a message (what the operator reads)",
        "una alarma necesita un mensaje (lo que lee el operador)",
    ),
    (
        Code::AlarmFile,
        "an alarm row has {} fields, this one has {}",
        "una fila de alarma tiene {0} campos; esta tiene {1}",
    ),
    (Code::AlarmFile, "more than {} alarms", "más de {0} alarmas"),
    (
        Code::StDeclaration,
        "EXIT is only allowed inside FOR, WHILE or REPEAT",
        "EXIT solo se permite dentro de FOR, WHILE o REPEAT",
    ),
    (Code::StDeclaration, "`{}` is CONSTANT", "`{0}` es CONSTANT"),
    (
        Code::StDeclaration,
        "the loop variable `{}` is a writable integer variable",
        "la variable del bucle `{0}` es una variable entera que se puede escribir",
    ),
    (
        Code::StType,
        "CASE selects on an integer, not a {}",
        "CASE selecciona por un entero, no por un {0}",
    ),
    (Code::StType, "MOD does not take TIME", "MOD no admite TIME"),
    (Code::StType, "MOD takes integers, not {}", "MOD admite enteros, no {0}"),
    (Code::StType, "MUX", "MUX"),
    (
        Code::StType,
        "MUX's selector is an integer",
        "el selector de MUX es un entero",
    ),
    (Code::StType, "N", "N"),
    (
        Code::StType,
        "NOT takes a BOOL or a bit string (BYTE … LWORD), not {}",
        "NOT admite un BOOL o una cadena de bits (BYTE … LWORD), no {0}",
    ),
    (Code::StType, "SEL's selector is BOOL", "el selector de SEL es BOOL"),
    (
        Code::StType,
        "T#{}ms does not fit a TIME (32-bit milliseconds)",
        "T#{0}ms no cabe en un TIME (milisegundos de 32 bits)",
    ),
    (
        Code::StType,
        "TIME {} TIME is not defined; scale a TIME by an integer",
        "TIME {0} TIME no está definido; escale un TIME por un entero",
    ),
    (
        Code::StType,
        "TRUNC takes a REAL or LREAL, not {}",
        "TRUNC admite un REAL o LREAL, no {0}",
    ),
    (Code::StType, "TRUNC takes a REAL", "TRUNC admite un REAL"),
    (
        Code::StType,
        "`**` takes REAL or LREAL, not {}; convert with {}_TO_REAL",
        "`**` admite REAL o LREAL, no {0}; convierta con {1}_TO_REAL",
    ),
    (
        Code::StType,
        "`-` takes a number, not a {}",
        "`-` admite un número, no un {0}",
    ),
    (
        Code::StType,
        "`.{}`: this has no members",
        "`.{0}`: esto no tiene miembros",
    ),
    (
        Code::StType,
        "`{}` cannot be assigned as a whole",
        "`{0}` no se puede asignar entero",
    ),
    (
        Code::StType,
        "`{}` does not take bit strings ({}); convert to an unsigned integer first",
        "`{0}` no admite cadenas de bits ({1}); convierta antes a un entero sin signo",
    ),
    (
        Code::StType,
        "`{}` does not take enumeration values ({})",
        "`{0}` no admite valores de enumeración ({1})",
    ),
    (Code::StType, "`{}` has no members", "`{0}` no tiene miembros"),
    (
        Code::StType,
        "`{}` is a BOOL; it has no members",
        "`{0}` es un BOOL; no tiene miembros",
    ),
    (
        Code::StType,
        "`{}` is a FUNCTION_BLOCK type: declare an instance (`x : {};`) and call the instance",
        "`{0}` es un tipo FUNCTION_BLOCK: declare una instancia (`x : {1};`) y llame a la instancia",
    ),
    (
        Code::StType,
        "`{}` is a TIMER, COUNTER or PID tag, not {}",
        "`{0}` es una variable TIMER, COUNTER o PID, no {1}",
    ),
    (
        Code::StType,
        "`{}` is a function block instance: call it as a statement (`{}(…);`) and read its outputs",
        "`{0}` es una instancia de bloque de función: llámela como sentencia (`{1}(…);`) y lea sus salidas",
    ),
    (
        Code::StType,
        "`{}` is a whole {}; index it",
        "`{0}` es un {1} entero; indéxelo",
    ),
    (
        Code::StType,
        "`{}` is a whole {}; read a member",
        "`{0}` es un {1} entero; lea un miembro",
    ),
    (
        Code::StType,
        "`{}` is a {} instance; call it or read a member",
        "`{0}` es una instancia de {1}; llámela o lea un miembro",
    ),
    (
        Code::StType,
        "`{}` is a {} instance; call it or read an output",
        "`{0}` es una instancia de {1}; llámela o lea una salida",
    ),
    (
        Code::StType,
        "`{}` is an array; it has no members",
        "`{0}` es un array; no tiene miembros",
    ),
    (
        Code::StType,
        "`{}` is declared {} here but the global is {}",
        "`{0}` está declarada aquí como {1} pero la global es {2}",
    ),
    (Code::StType, "`{}` is given twice", "`{0}` se da dos veces"),
    (Code::StType, "`{}` is not a variable", "`{0}` no es una variable"),
    (Code::StType, "`{}` is not an array", "`{0}` no es un array"),
    (
        Code::StType,
        "`{}` is {}: its bits are `.0` to `.{}`, not `.{}`",
        "`{0}` es {1}: sus bits van de `.0` a `.{2}`, no `.{3}`",
    ),
    (
        Code::StType,
        "`{}` is {}; it has no members",
        "`{0}` es {1}; no tiene miembros",
    ),
    (
        Code::StType,
        "`{}` of {} and {}: the types differ; convert one (for example {}_TO_{})",
        "`{0}` de {1} y {2}: los tipos difieren; convierta uno (por ejemplo {3}_TO_{4})",
    ),
    (
        Code::StType,
        "`{}` takes numbers, not {} and {}",
        "`{0}` admite números, no {1} y {2}",
    ),
    (
        Code::StType,
        "a BOOL where a {} is wanted",
        "un BOOL donde se quiere un {0}",
    ),
    (
        Code::StType,
        "a CASE label does not fit a DINT",
        "una etiqueta de CASE no cabe en un DINT",
    ),
    (
        Code::StType,
        "a CASE label is an integer literal or a range of them",
        "una etiqueta de CASE es un literal entero o un rango de ellos",
    ),
    (Code::StType, "a bit is a BOOL, not {}", "un bit es un BOOL, no {0}"),
    (
        Code::StType,
        "a condition is BOOL, not {}",
        "una condición es BOOL, no {0}",
    ),
    (
        Code::StType,
        "an index is SINT, INT or DINT, not {}",
        "un índice es SINT, INT o DINT, no {0}",
    ),
    (
        Code::StType,
        "an index is an integer, not {}",
        "un índice es un entero, no {0}",
    ),
    (
        Code::StType,
        "cannot assign this to `{}`, {}",
        "no se puede asignar esto a `{0}`, {1}",
    ),
    (
        Code::StType,
        "cannot assign {} to `{}`, {}",
        "no se puede asignar {0} a `{1}`, {2}",
    ),
    (
        Code::StType,
        "cannot assign {} to `{}`, {}; convert it (for example {}_TO_{})",
        "no se puede asignar {0} a `{1}`, {2}; conviértalo (por ejemplo {3}_TO_{4})",
    ),
    (
        Code::StType,
        "cannot assign {} to {} element; convert it",
        "no se puede asignar {0} a un elemento ({1}); conviértalo",
    ),
    (Code::StType, "enumeration", "enumeración"),
    (Code::StType, "index", "índice"),
    (Code::StType, "selector", "selector"),
    (
        Code::StType,
        "the array has {} dimension(s), not {}",
        "el array tiene {0} dimensión(es), no {1}",
    ),
    (
        Code::StType,
        "the index {} is outside the bounds {}..{}",
        "el índice {0} está fuera de los límites {1}..{2}",
    ),
    (
        Code::StType,
        "the loop variable is a {}; the end value is a {}",
        "la variable del bucle es un {0}; el valor final es un {1}",
    ),
    (
        Code::StType,
        "the loop variable is a {}; the start value is a {}",
        "la variable del bucle es un {0}; el valor inicial es un {1}",
    ),
    (
        Code::StType,
        "the range {}..{} is empty",
        "el rango {0}..{1} está vacío",
    ),
    (Code::StType, "{} does not fit a {}", "{0} no cabe en un {1}"),
    (
        Code::StType,
        "{} of {} and {}: the types differ",
        "{0} de {1} y {2}: los tipos difieren",
    ),
    (
        Code::StType,
        "{} shifts a bit string (BYTE … LWORD), not {}",
        "{0} desplaza una cadena de bits (BYTE … LWORD), no {1}",
    ),
    (
        Code::StType,
        "{} takes BOOL operands, not {} and {} (bit strings are not supported yet)",
        "{0} admite operandos BOOL, no {1} y {2} (las cadenas de bits aún no están disponibles)",
    ),
    (
        Code::StType,
        "{} takes REAL or LREAL operands, not {} and {}",
        "{0} admite operandos REAL o LREAL, no {1} y {2}",
    ),
    (
        Code::StType,
        "{} takes a REAL or LREAL, not {}; convert it ({}_TO_REAL)",
        "{0} admite un REAL o LREAL, no {1}; conviértalo ({2}_TO_REAL)",
    ),
    (
        Code::StType,
        "{} takes a number, not BOOL",
        "{0} admite un número, no BOOL",
    ),
    (Code::StType, "{} takes a {}, not BOOL", "{0} admite un {1}, no BOOL"),
    (Code::StType, "{} takes a {}, not a {}", "{0} admite un {1}, no un {2}"),
    (
        Code::StType,
        "{} takes numbers, not BOOL",
        "{0} admite números, no BOOL",
    ),
    (
        Code::StType,
        "{} takes {} argument(s), not {}",
        "{0} lleva {1} argumento(s), no {2}",
    ),
    (Code::StType, "{} takes {} arguments", "{0} lleva {1} argumentos"),
    (Code::StType, "{} takes {} input(s)", "{0} lleva {1} entrada(s)"),
    (
        Code::StType,
        "{}'s N is an integer, not BOOL",
        "la N de {0} es un entero, no BOOL",
    ),
    (
        Code::StType,
        "{}'s N is an integer, not {}",
        "la N de {0} es un entero, no {1}",
    ),
    (
        Code::StType,
        "{}'s first argument is {}, not {}",
        "el primer argumento de {0} es {1}, no {2}",
    ),
    (Code::StType, "{}.{} is a {}, not a {}", "{0}.{1} es un {2}, no un {3}"),
    (
        Code::StNotSupported,
        "a pragma `{}` is not run: OpenPLC and Beremiz paste its text into their generated C code, and Alba runs no C code",
        "un pragma `{0}` no se ejecuta: OpenPLC y Beremiz pegan su texto en el código C que generan, y Alba no ejecuta código C",
    ),
    (
        Code::StSyntax,
        "this pragma `{` is never closed by `}`",
        "este pragma `{` nunca se cierra con `}`",
    ),
    (
        Code::StNotSupported,
        "{}: `{}` is not an elementary type",
        "{0}: `{1}` no es un tipo elemental",
    ),
    (
        Code::StNotSupported,
        "{}: a string converts only to numbers, bit strings, BOOL, durations and dates",
        "{0}: una cadena solo se convierte en números, cadenas de bits, BOOL, duraciones y fechas",
    ),
    (
        Code::StType,
        "{}: BCD conversions are between a bit string and an integer",
        "{0}: las conversiones BCD son entre una cadena de bits y un entero",
    ),
    (Code::PnmlNumber, "{} is empty", "{0} está vacío"),
    (
        Code::PnmlNumber,
        "{} `{}` is far too large",
        "{0} `{1}` es demasiado grande",
    ),
    (
        Code::PnmlNumber,
        "{} `{}` is not a whole number",
        "{0} `{1}` no es un número entero",
    ),
    (Code::PnmlNumber, "{} `{}` is not a number", "{0} `{1}` no es un número"),
    (
        Code::TomlSyntax,
        "alba.toml: string values must be quoted, expected literal string",
        "alba.toml: los valores de texto van entre comillas",
    ),
    (
        Code::TomlSyntax,
        "alba.toml: invalid basic string, expected `\"`",
        "alba.toml: cadena no válida; se esperaba `\"`",
    ),
    (
        Code::TomlSyntax,
        "alba.toml: {}",
        "alba.toml no es TOML válido (en palabras del lector de TOML): {0}",
    ),
    (
        Code::ConfigField,
        "alba.toml: missing field `{}`",
        "alba.toml: falta el campo `{0}`",
    ),
    (
        Code::ConfigField,
        "alba.toml: unknown field `{}`, expected one of {}",
        "alba.toml: campo desconocido `{0}`; se esperaba uno de {1}",
    ),
    (
        Code::ConfigField,
        "alba.toml: unknown field `{}`, expected {}",
        "alba.toml: campo desconocido `{0}`; se esperaba {1}",
    ),
    (
        Code::ConfigField,
        "alba.toml: invalid type: {}, expected {}",
        "alba.toml: tipo no válido: {0}; se esperaba {1}",
    ),
    (
        Code::ConfigField,
        "alba.toml: invalid value: {}, expected {}",
        "alba.toml: valor no válido: {0}; se esperaba {1}",
    ),
    (
        Code::ConfigField,
        "{} has no PWM, so it cannot be an analog output",
        "{0} no tiene PWM, así que no puede ser una salida analógica",
    ),
    (
        Code::ConfigField,
        "broker = \"{}\" is not a host and port",
        "broker = \"{0}\" no es un host y un puerto",
    ),
    (
        Code::ConfigField,
        "topic_prefix = \"{}\" is not a topic prefix",
        "topic_prefix = \"{0}\" no es un prefijo de tema",
    ),
    (
        Code::ConfigField,
        "username and password_file go together",
        "username y password_file van juntos",
    ),
    (
        Code::ProgramFile,
        "`{}` leaves the project folder",
        "`{0}` sale de la carpeta del proyecto",
    ),
    (
        Code::ProgramFile,
        "`{}` is listed twice",
        "`{0}` está listado dos veces",
    ),
    (
        Code::ProgramFile,
        "`{}` has no known program extension",
        "`{0}` no tiene una extensión de programa conocida",
    ),
    (Code::ProgramFile, "cannot read {}: {}", "no se puede leer {0}: {1}"),
    (
        Code::BoardPin,
        "`{}` ({}) is pin {}, but the {} has no pin {} ({}); {}",
        "`{0}` ({1}) es el pin {2}, pero la {3} no tiene pin {4} ({5}); {6}",
    ),
    (
        Code::BoardPin,
        "`{}` ({}) is not wired: the pin map has {} channels there ({} to {})",
        "`{0}` ({1}) no está cableada: el mapa de pines tiene ahí {2} canales ({3} a {4})",
    ),
    (
        Code::PlantModel,
        "a plant model cannot write `{}`: it is an output of the program",
        "un modelo de planta no puede escribir `{0}`: es una salida del programa",
    ),
    (
        Code::PlantModel,
        "{} = {} must be a number 0 or more",
        "{0} = {1} debe ser un número mayor o igual que 0",
    ),
    (
        Code::PlantModel,
        "{} = {} must be a number more than 0",
        "{0} = {1} debe ser un número mayor que 0",
    ),
    (
        Code::PlantModel,
        "drain = \"{}\" is not a drain law",
        "drain = \"{0}\" no es una ley de vaciado",
    ),
    (
        Code::CsvSyntax,
        "this quote is never closed",
        "estas comillas nunca se cierran",
    ),
    (
        Code::PidParameter,
        "PID parameter {} = {}: {}",
        "parámetro PID {0} = {1}: {2}",
    ),
    (
        Code::AlarmFile,
        "`{}` is not a condition: write on, off, rising, falling, or > >= < <= == != and a number",
        "`{0}` no es una condición: escriba on, off, rising, falling, o > >= < <= == != y un número",
    ),
    (
        Code::AlarmFile,
        "`{}` is not a severity: write 1 to 1000, or low, medium, high or critical",
        "`{0}` no es una severidad: escriba de 1 a 1000, o low, medium, high o critical",
    ),
    (
        Code::LogicStack,
        "{} needs a value on the logic stack, which is empty here",
        "{0} necesita un valor en la pila lógica, que aquí está vacía",
    ),
    (
        Code::LogicStack,
        "{} needs {} values on the logic stack, which holds {} here",
        "{0} necesita {1} valores en la pila lógica, que aquí contiene {2}",
    ),
    (
        Code::S7Timer,
        "{} is a TONR timer; TON and TOF use T32–T63 and T96–T255",
        "{0} es un temporizador TONR; TON y TOF usan T32–T63 y T96–T255",
    ),
    (
        Code::S7Timer,
        "{} is a TON/TOF timer; TONR uses T0–T31 and T64–T95",
        "{0} es un temporizador TON/TOF; TONR usa T0–T31 y T64–T95",
    ),
    (
        Code::StSyntax,
        "`{}` is not a duration; write it like T#1h2m3s, T#1.5s or T#250ms",
        "`{0}` no es una duración; escríbala como T#1h2m3s, T#1.5s o T#250ms",
    ),
    (
        Code::StSyntax,
        "this comment `(*` is never closed by `*)`",
        "este comentario `(*` nunca se cierra con `*)`",
    ),
    (
        Code::StSyntax,
        "this string is not closed on its line",
        "esta cadena no se cierra en su línea",
    ),
    (Code::StSyntax, "unexpected character `{}`", "carácter inesperado `{0}`"),
    (
        Code::Expression,
        "expected a value, found `{}`",
        "se esperaba un valor; hay `{0}`",
    ),
    (
        Code::Expression,
        "the expression ends too early: expected a value",
        "la expresión termina demasiado pronto: se esperaba un valor",
    ),
    (
        Code::BadArgument,
        "invalid value '{}' for '{}': {}",
        "valor no válido '{0}' para '{1}': {2}",
    ),
    (
        Code::NetPlaceTag,
        "place `{}` cannot drive `{}`: it is an input, written only by the I/O (or a plant model)",
        "el lugar `{0}` no puede escribir `{1}`: es una entrada, que solo escribe la E/S (o un modelo de planta)",
    ),
    (
        Code::NetPlaceTag,
        "place `{}` drives `{}`, which is a {}, not a BOOL",
        "el lugar `{0}` escribe `{1}`, que es un {2}, no un BOOL",
    ),
    (
        Code::NetPlaceTag,
        "place `{}` drives unknown tag `{}`",
        "el lugar `{0}` escribe una variable desconocida `{1}`",
    ),
    (
        Code::NetElement,
        "the delay `{}` is negative",
        "el retardo `{0}` es negativo",
    ),
    (
        Code::SfcStructure,
        "an SFC has one initial step; `{}` is another",
        "un SFC tiene una sola etapa inicial; `{0}` es otra",
    ),
    (
        Code::SfcStructure,
        "an SFC needs one INITIAL_STEP",
        "un SFC necesita un INITIAL_STEP",
    ),
    (Code::SfcStructure, "no step `{}`", "no hay ninguna etapa `{0}`"),
    (
        Code::SfcStructure,
        "the qualifier {} needs a time: `{}`",
        "el calificador {0} necesita un tiempo: `{1}`",
    ),
    (
        Code::SfcStructure,
        "the qualifier {} takes no time",
        "el calificador {0} no lleva tiempo",
    ),
    // SFC actions and conditions in ST.
    (
        Code::NetTagClash,
        "the action flag `{}` is already a tag",
        "el indicador de acción `{0}` ya es una variable",
    ),
    (
        Code::NetTagClash,
        "the condition flag `{}` is already a tag",
        "el indicador de condición `{0}` ya es una variable",
    ),
    (
        Code::SfcSyntax,
        "a condition in ST is one expression",
        "una condición en ST es una sola expresión",
    ),
    (
        Code::SfcSyntax,
        "`{}` is not an action name",
        "`{0}` no es un nombre de acción",
    ),
    (
        Code::SfcSyntax,
        "the action is not ended by END_ACTION",
        "la acción no termina con END_ACTION",
    ),
    (
        Code::SfcSyntax,
        "the condition is not ended by END_TRANSITION",
        "la condición no termina con END_TRANSITION",
    ),
    // ST strings.
    (
        Code::StType,
        "`{}` is {}; it has no members (LEN gives its length)",
        "`{0}` es {1}; no tiene miembros (LEN da su longitud)",
    ),
    (
        Code::StType,
        "a string where a {} is wanted",
        "una cadena donde se espera un {0}",
    ),
    // Coloured nets (PNML symmetric nets) unfolded for the analysis.
    (
        Code::PnmlArc,
        "arc from `{}` to `{}` does not join a place and a transition of the net",
        "el arco de `{0}` a `{1}` no une un lugar y una transición de la red",
    ),
    (
        Code::PnmlDuplicateId,
        "the constant `{}` is declared twice",
        "la constante `{0}` está declarada dos veces",
    ),
    (
        Code::PnmlDuplicateId,
        "the sort `{}` is declared twice",
        "el tipo de color `{0}` está declarado dos veces",
    ),
    (
        Code::PnmlDuplicateId,
        "the variable `{}` is declared twice",
        "la variable `{0}` está declarada dos veces",
    ),
    (
        Code::PnmlLimit,
        "a sort of {} colours: Alba unfolds sorts of 1 to {} colours",
        "un tipo de {0} colores: Alba despliega tipos de 1 a {1} colores",
    ),
    (
        Code::PnmlLimit,
        "this term denotes {} colours; Alba unfolds at most {}",
        "este término denota {0} colores; Alba despliega como mucho {1}",
    ),
    (
        Code::PnmlLimit,
        "unfolding `{}` needs {} bindings of its variables; Alba tries at most {} in a net",
        "desplegar `{0}` necesita {1} asignaciones de sus variables; Alba prueba como mucho {2} en una red",
    ),
    (
        Code::PnmlLimit,
        "unfolding the coloured net makes more than {} places, transitions and arcs",
        "desplegar la red coloreada da más de {0} lugares, transiciones y arcos",
    ),
    (
        Code::PnmlNumber,
        "`{}` of <{}> is `{}`, not a whole number",
        "`{0}` de <{1}> es `{2}`, no un número entero",
    ),
    (
        Code::PnmlNumber,
        "binding `{}`: an arc of weight {}",
        "asignación `{0}`: un arco de peso {1}",
    ),
    (
        Code::PnmlNumber,
        "the initial marking of `{}` has {} tokens of a colour",
        "el marcado inicial de `{0}` tiene {1} marcas de un color",
    ),
    (
        Code::PnmlNumber,
        "the range {}..{} is empty or too large",
        "el rango {0}..{1} está vacío o es demasiado grande",
    ),
    (
        Code::PnmlNumber,
        "{} is outside its range",
        "{0} está fuera de su rango",
    ),
    (
        Code::PnmlNumber,
        "{} tokens: a count is from 0 to {}",
        "{0} marcas: una cuenta va de 0 a {1}",
    ),
    (Code::PnmlStructure, "<{}> compares colours", "<{0}> compara colores"),
    (
        Code::PnmlStructure,
        "<{}> has no <structure>",
        "<{0}> no tiene <structure>",
    ),
    (Code::PnmlStructure, "<{}> has no `{}`", "<{0}> no tiene `{1}`"),
    (
        Code::PnmlStructure,
        "<{}> holds one sort or term",
        "<{0}> contiene un tipo o un término",
    ),
    (
        Code::PnmlStructure,
        "<{}> is not a {} Alba can unfold",
        "<{0}> no es un {1} que Alba sepa desplegar",
    ),
    (
        Code::PnmlStructure,
        "<{}> of a term that is not one enumeration or range value",
        "<{0}> de un término que no es un valor de una enumeración o de un rango",
    ),
    (
        Code::PnmlStructure,
        "<{}> takes two <subterm>s, not {}",
        "<{0}> lleva dos <subterm>, no {1}",
    ),
    (
        Code::PnmlStructure,
        "`{}` is not a declared constant",
        "`{0}` no es una constante declarada",
    ),
    (
        Code::PnmlStructure,
        "a comparison of more than one colour",
        "una comparación de más de un color",
    ),
    (
        Code::PnmlStructure,
        "a condition is a boolean term",
        "una condición es un término booleano",
    ),
    (
        Code::PnmlStructure,
        "a multiset or condition where a colour is expected",
        "un multiconjunto o una condición donde se espera un color",
    ),
    (
        Code::PnmlStructure,
        "a tuple's parts are colours",
        "las partes de una tupla son colores",
    ),
    (
        Code::PnmlStructure,
        "an arc of the coloured place `{}` has no <hlinscription>",
        "un arco del lugar coloreado `{0}` no tiene <hlinscription>",
    ),
    (
        Code::PnmlStructure,
        "the first part of a numberof is a <numberconstant>",
        "la primera parte de un numberof es un <numberconstant>",
    ),
    (
        Code::PnmlStructure,
        "the initial marking of `{}` has a colour not of its sort",
        "el marcado inicial de `{0}` tiene un color que no es de su tipo",
    ),
    (
        Code::PnmlStructure,
        "the inscription's colour is not of the sort of `{}`",
        "el color de la inscripción no es del tipo de `{0}`",
    ),
    (
        Code::PnmlStructure,
        "the sort `{}` is not declared",
        "el tipo de color `{0}` no está declarado",
    ),
    (
        Code::PnmlStructure,
        "the sorts refer to each other in a cycle",
        "los tipos de color se refieren unos a otros en un ciclo",
    ),
    (
        Code::PnmlStructure,
        "the variable `{}` is not declared",
        "la variable `{0}` no está declarada",
    ),
    (Code::PnmlSyntax, "not well-formed XML", "XML mal formado"),
    (
        Code::PnmlStructure,
        "a coloured net (symmetric net): the editor and the scan read place/transition nets",
        "una red coloreada (red simétrica): el editor y el ciclo leen redes de lugares y transiciones",
    ),
    // Scheduled reports.
    (
        Code::ConfigField,
        "`[reports]` needs `shift_hours` or `period_hours`",
        "`[reports]` necesita `shift_hours` o `period_hours`",
    ),
    (
        Code::ConfigField,
        "`[reports]` sets both `shift_hours` and `period_hours`",
        "`[reports]` fija a la vez `shift_hours` y `period_hours`",
    ),
    (Code::ConfigField, "`folder` is empty", "`folder` está vacío"),
    (Code::ConfigField, "`formats` is empty", "`formats` está vacío"),
    (Code::ConfigField, "`shift_hours` is empty", "`shift_hours` está vacío"),
    (
        Code::ConfigField,
        "hour {} is listed twice in `shift_hours`",
        "la hora {0} aparece dos veces en `shift_hours`",
    ),
    (
        Code::ConfigField,
        "period_hours = {} does not divide a day",
        "period_hours = {0} no divide un día",
    ),
    (
        Code::ConfigField,
        "shift hour {} is out of range",
        "la hora de turno {0} está fuera de rango",
    ),
];

/// Messages of the shared readers — addresses, literals, tag names, the
/// resolution of a name — that sites of many codes pass on as they are
/// (`unknown tag `X`` is E301 in a rung, E402 in a stimulus, E621 in a guard):
/// (English pattern, Spanish), tried for any code after its own [`MESSAGES`].
pub const SHARED: &[(&str, &str)] = &[
    ("unknown tag `{}`", "variable desconocida `{0}`"),
    (
        "{} `{}` has no member `{}` (members: {})",
        "{0} `{1}` no tiene el miembro `{2}` (miembros: {3})",
    ),
    (
        "`{}` is a {}, not a structure with members",
        "`{0}` es un {1}, no una estructura con miembros",
    ),
    (
        "{} is outside this project's I/O image",
        "{0} está fuera de la imagen de E/S de este proyecto",
    ),
    // addresses (alba-model's address.rs and address/slc.rs)
    (
        "`{}`: expected a number for the channel",
        "`{0}`: se esperaba un número de canal",
    ),
    (
        "`{}`: expected a number for the word",
        "`{0}`: se esperaba un número de palabra",
    ),
    (
        "`{}`: expected a number for the byte",
        "`{0}`: se esperaba un número de byte",
    ),
    (
        "`{}`: expected a number for the bit",
        "`{0}`: se esperaba un número de bit",
    ),
    (
        "`{}`: expected a number for the double word",
        "`{0}`: se esperaba un número de doble palabra",
    ),
    (
        "`{}`: expected a number for the {}",
        "`{0}`: se esperaba un número para {1}",
    ),
    (
        "`{}`: expected byte.bit, like 0.3",
        "`{0}`: se esperaba byte.bit, como 0.3",
    ),
    (
        "`{}`: bit numbers go from 0 to 7",
        "`{0}`: los números de bit van de 0 a 7",
    ),
    (
        "`{}`: digital channels go from 0 to {}",
        "`{0}`: los canales digitales van de 0 a {1}",
    ),
    (
        "`{}`: analog channels go from 0 to {}",
        "`{0}`: los canales analógicos van de 0 a {1}",
    ),
    (
        "`{}`: marker memory has {} bytes (0 to {})",
        "`{0}`: la memoria de marcas tiene {1} bytes (0 a {2})",
    ),
    (
        "`{}`: unknown area `{}`; AuroraLD addresses are DI:1/n, DO:2/n, AI:3/n or AO:4/n",
        "`{0}`: área desconocida `{1}`; las direcciones de AuroraLD son DI:1/n, DO:2/n, AI:3/n o AO:4/n",
    ),
    (
        "`{}`: {} addresses use slot {} ({}:{}/n)",
        "`{0}`: las direcciones {1} usan la ranura {2} ({3}:{4}/n)",
    ),
    (
        "`{}`: expected a size X, B, W or D after %{}",
        "`{0}`: se esperaba un tamaño X, B, W o D después de %{1}",
    ),
    (
        "`{}`: %{}{} is not an address Alba knows",
        "`{0}`: %{1}{2} no es una dirección que Alba conozca",
    ),
    (
        "`{}`: IEC addresses start with %I, %Q or %M",
        "`{0}`: las direcciones IEC empiezan por %I, %Q o %M",
    ),
    (
        "`{}`: S7 analog words are even (AIW0, AIW2, ...)",
        "`{0}`: las palabras analógicas del S7 son pares (AIW0, AIW2, ...)",
    ),
    (
        "`{}`: S7 analog words are even (AQW0, AQW2, ...)",
        "`{0}`: las palabras analógicas del S7 son pares (AQW0, AQW2, ...)",
    ),
    (
        "`{}`: a bit file has {} bits (B{}/0 to B{}/{})",
        "`{0}`: un archivo de bits tiene {1} bits (B{2}/0 a B{3}/{4})",
    ),
    (
        "`{}`: a {} element is {}{}:e or {}{}:e.MEMBER (like {}{}:0.{})",
        "`{0}`: un elemento {1} es {2}{3}:e o {4}{5}:e.MIEMBRO (como {6}{7}:0.{8})",
    ),
    (
        "`{}`: file numbers go from 0 to 255",
        "`{0}`: los números de archivo van de 0 a 255",
    ),
    ("`{}`: elements go from 0 to {}", "`{0}`: los elementos van de 0 a {1}"),
    (
        "`{}`: elements go from 0 to {} ({}{}:0 to {}{}:{})",
        "`{0}`: los elementos van de 0 a {1} ({2}{3}:0 a {4}{5}:{6})",
    ),
    (
        "`{}`: Alba maps the bits of the SLC 500's I/O words ({}:e/b, b from 0 to 15), not whole words; use an analog address (AI:3/n, AO:4/n) for a value",
        "`{0}`: Alba asigna los bits de las palabras de E/S del SLC 500 ({1}:e/b, b de 0 a 15), no palabras enteras; use una dirección analógica (AI:3/n, AO:4/n) para un valor",
    ),
    (
        "`{}`: Alba maps one 16-bit word per slot ({}:e.0/b, or {}:e/b)",
        "`{0}`: Alba asigna una palabra de 16 bits por ranura ({1}:e.0/b, o {2}:e/b)",
    ),
    (
        "`{}`: bits of an SLC 500 word go from 0 to 15",
        "`{0}`: los bits de una palabra del SLC 500 van de 0 a 15",
    ),
    (
        "`{}`: slots go from 0 to {} (16 channels each)",
        "`{0}`: las ranuras van de 0 a {1} (16 canales cada una)",
    ),
    (
        "`{}`: Alba maps the SLC 500 data files {} and the timer and counter files (T4, C5); {}{} is not one of them",
        "`{0}`: Alba asigna los archivos de datos del SLC 500 {1} y los de temporizadores y contadores (T4, C5); {2}{3} no es uno de ellos",
    ),
    (
        "`{}`: a float (F) element has no bits",
        "`{0}`: un elemento de coma flotante (F) no tiene bits",
    ),
    // literals (alba-model's value.rs)
    ("`{}` is not a number", "`{0}` no es un número"),
    (
        "`{}`: the base of a based literal is 2, 8, 10 or 16",
        "`{0}`: la base de un literal con base es 2, 8, 10 o 16",
    ),
    (
        "`{}` is not a valid base-{} number",
        "`{0}` no es un número válido en base {1}",
    ),
    ("`{}` does not fit in 64 bits", "`{0}` no cabe en 64 bits"),
    ("`{}` is too large", "`{0}` es demasiado grande"),
    (
        "`{}`: write a digit after the decimal point",
        "`{0}`: escriba una cifra después del punto decimal",
    ),
    (
        "{} is out of range for {} ({} to {})",
        "{0} está fuera del rango de {1} ({2} a {3})",
    ),
    ("{} is out of range for REAL", "{0} está fuera del rango de REAL"),
    ("{} takes an integer, not a real", "{0} admite un entero, no un real"),
    (
        "{} takes a number, not a boolean",
        "{0} admite un número, no un booleano",
    ),
    ("{} does not take a duration", "{0} no admite una duración"),
    (
        "{} is a structure and takes no single value",
        "{0} es una estructura y no admite un único valor",
    ),
    (
        "`{}` is not a duration; write it like T#1m30s or T#250ms",
        "`{0}` no es una duración; escríbala como T#1m30s o T#250ms",
    ),
    (
        "`{}` is beyond the DINT range; only a LINT or LREAL instruction takes it",
        "`{0}` está fuera del rango DINT; solo una instrucción LINT o LREAL lo admite",
    ),
    // tag names (alba-model's tags.rs)
    (
        "`{}` is not a valid tag name: use letters, digits and `_`, not starting with a digit",
        "`{0}` no es un nombre de variable válido: use letras, dígitos y `_`, sin empezar por un dígito",
    ),
    ("`{}` is longer than {} characters", "`{0}` tiene más de {1} caracteres"),
    ("`{}` is a reserved word", "`{0}` es una palabra reservada"),
    ("the tag name is empty", "el nombre de la variable está vacío"),
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
    // the nets analysis's notes and `stopped` (alba-net), worded by the server for the studio
    (
        "guards, priorities and tags are ignored: this is the analysis of the underlying place/transition net",
        "no se tienen en cuenta las guardas, las prioridades ni las variables: es el análisis de la red de lugares y transiciones subyacente",
    ),
    (
        "inhibitor arcs: unboundedness is concluded only from growth of places without inhibitor arcs; otherwise the boundedness is reported unknown",
        "arcos inhibidores: que la red no está acotada solo se concluye del crecimiento de lugares sin arcos inhibidores; si no, la acotación se da como desconocida",
    ),
    (
        "the explicit exploration was skipped: the symbolic engine counted {} states, more than it can hold ({} states, --max-states, or {} MiB at {} bytes a state at least, --memory)",
        "se omitió la exploración explícita: el motor simbólico contó {0} estados, más de los que puede guardar ({1} estados, --max-states, o {2} MiB a {3} bytes por estado como mínimo, --memory)",
    ),
    (
        "states ({}), edges ({}), place bounds, most tokens per marking, deadlocks, dead transitions, liveness and reversibility come from the symbolic engine (decision diagrams)",
        "los estados ({0}), los arcos ({1}), las cotas de los lugares, el máximo de marcas por marcado, los bloqueos, las transiciones muertas, la vivacidad y la reversibilidad vienen del motor simbólico (diagramas de decisión)",
    ),
    (
        "{} dead markings (more than 2^64)",
        "{0} marcados muertos (más de 2^64)",
    ),
    (
        "the symbolic engine did not decide {} ({})",
        "el motor simbólico no decidió {0} ({1})",
    ),
    (
        "the firing sequence to a deadlock is not always a shortest one: the symbolic engine's breadth-first layers did not fit its budget, it was found by chaining",
        "la secuencia de disparos hasta un bloqueo no es siempre una de las más cortas: las capas en anchura del motor simbólico no cabían en su presupuesto, se encontró encadenando",
    ),
    (
        "symbolic engine stopped ({}) after {} nodes, {} s",
        "el motor simbólico se detuvo ({0}) tras {1} nodos, {2} s",
    ),
    (
        "unbounded: Karp–Miller coverability graph; states counts its nodes; edges, deadlocks and reversibility are not computed",
        "no acotada: grafo de cobertura de Karp–Miller; los estados cuentan sus nodos; no se calculan los arcos, los bloqueos ni la reversibilidad",
    ),
    ("cancelled", "cancelado"),
    ("cancelled after {} states", "cancelado tras {0} estados"),
    (
        "the net is unbounded and its coverability graph has more than {} nodes (--max-states)",
        "la red no está acotada y su grafo de cobertura tiene más de {0} nodos (--max-states)",
    ),
    (
        "place {} would be unbounded but an inhibitor arc reads it: the coverability graph would not be sound, boundedness unknown",
        "el lugar {0} no estaría acotado, pero lo lee un arco inhibidor: el grafo de cobertura no sería correcto; acotación desconocida",
    ),
    (
        "stopped after {} states (--max-states): the state space is incomplete",
        "detenido tras {0} estados (--max-states): el espacio de estados está incompleto",
    ),
    (
        "stopped after {} states: the state space needs more than {} MiB (--memory)",
        "detenido tras {0} estados: el espacio de estados necesita más de {1} MiB (--memory)",
    ),
    (
        "a place count exceeds 2^32-1: boundedness unknown",
        "un lugar supera 2^32-1 marcas: acotación desconocida",
    ),
];

/// The Spanish explanation (`alba explain CODE --lang es`) of every code; a
/// test fails when a code lacks one.
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
    (
        Code::ConfigField,
        "alba.toml necesita `name` (una cadena) y `programs` (una lista de archivos de programa); son opcionales `scan_ms` (1..=60000, por defecto 10), `retain_ms` (10..=3600000, por defecto 1000), `description`, una tabla `[history]` (`enabled`, `retention_days` 0..=36500, `sample_ms`, `deadband` ≥ 0), una tabla `[modbus]` (`listen` = \"IP:PUERTO\", `max_connections` 1..=4096, `idle_timeout_s` 0..=86400, `unit_id` 0..=255, `allow` y `read_only` (vea E108), y `[modbus.tags]` con direcciones como \"hr 8192\"), una tabla `[opcua]` (`listen` = \"IP:PUERTO\", que necesita usuarios (users.toml) fuera de loopback; el obsoleto `[opcua.users]` con `nombre = \"<hash argon2 de alba hash-password>\"`, nunca una contraseña en claro; `read_only` lista algunos de ellos) y una tabla `[board]` (`model` = uno, nano o mega; `pinmap` = aurora, s7 u openplc). Las claves desconocidas se rechazan para que las erratas no pasen en silencio.",
    ),
    (
        Code::ProgramFile,
        "Cada entrada de `programs` debe nombrar, una sola vez, un archivo existente de la carpeta del proyecto con una extensión conocida (`.lad` para Ladder).",
    ),
    (
        Code::PlantModel,
        "Cada tabla `[[plant_model]]` de alba.toml simula un proceso sobre la E/S: `kind` es first_order (gain, tau), second_order (gain, den = [a2, a1, a0]), tank (area, inflow, outflow, sensor, max_level) o motor (r, l, kt, ke, j, b, sensor); `input` y `output` nombran la señal del actuador que lee y la medida que escribe (una variable, un miembro o una dirección; la salida debe ser una entrada o una variable interna). Opcionales: input_scale y output_scale = [raw_lo, raw_hi, lo, hi], saturation = [lo, hi] (límites del actuador), dead_time (0 a 600 s), noise (desviación típica) con seed, initial (la medida al empezar). Los tiempos y coeficientes deben ser números positivos; se rechazan los parámetros de otra clase. Vea docs/pid.md.",
    ),
    (
        Code::ModbusTag,
        "Cada entrada de `[modbus.tags]` de alba.toml da a una variable (o `Variable.MIEMBRO`, o una variable del sistema como `S:SCANMAX`) una dirección Modbus explícita según el mapa de OpenPLC: `Nombre = \"hr 8192\"`. El nombre debe existir; un BOOL va en una bobina o entrada discreta (`coil`, `di`), los números en registros (`hr`, `ir`: 1 registro para SINT/INT, 2 para DINT/REAL/TIME, 4 para LINT/LREAL, palabra alta primero); los clientes escriben bobinas y registros de retención, así que las entradas y las variables de solo lectura van en `di` o `ir`; dos entradas no pueden compartir un bit o un registro. Vea docs/protocols.md.",
    ),
    (
        Code::UsersFile,
        "Cada usuario de `users.toml` (junto a alba.toml) es una tabla `[users.NOMBRE]` con `role` (viewer, operator, engineer o admin) y `password`, el hash argon2 de la contraseña como cadena PHC (`$argon2id$...`), nunca la contraseña misma. Los nombres tienen de 1 a 64 letras, dígitos y `_ . - @`. Las claves desconocidas se rechazan. `alba user add|passwd|remove|role` escribe el archivo; vea docs/file-formats.md y docs/security.md. Un users.toml que otros usuarios de la máquina pueden leer o escribir (modo Unix más allá de 0600) se informa como aviso, no como error: `chmod 600 users.toml` (toda orden `alba user` lo guarda con 0600).",
    ),
    (
        Code::ModbusClients,
        "Modbus TCP no tiene autenticación, así que el servidor de `alba run` decide por la dirección del cliente. `[modbus] allow` lista los clientes atendidos: direcciones IPv4 o IPv6 (\"192.168.1.20\", \"::1\") y rangos CIDR (\"10.0.0.0/24\", \"fd00::/8\", con los bits de host a cero); la lista no puede estar vacía. Una dirección `listen` fuera de loopback (como 0.0.0.0) necesita `allow`; en loopback se atiende a todo cliente local salvo que `allow` diga otra cosa. `read_only = true` rechaza toda escritura. Vea docs/security.md.",
    ),
    (
        Code::OpcuaUsersDeprecated,
        "Los usuarios de `[opcua.users]` en alba.toml siguen funcionando (los de read_only como viewers, los demás como operators), pero los usuarios viven ahora en `users.toml`, un único almacén para todas las interfaces. Es un aviso: el proyecto se carga y se ejecuta. Pase cada usuario con `alba user add <proyecto> <nombre> --role operator` (tecleando otra vez la contraseña), o con `alba user migrate <proyecto>`, que copia los hashes en users.toml; después borre `[opcua.users]` y `read_only` de alba.toml. Un nombre presente en los dos archivos toma su entrada de users.toml.",
    ),
    (
        Code::BadAddress,
        "Las direcciones nombran la imagen de E/S: DI:1/n DO:2/n AI:3/n AO:4/n (AuroraLD), %IXb.i %QXb.i %IWn %QWn %MXb.i %MBn %MWn %MDn (IEC 61131-3), Ib.i Qb.i AIWn AQWn Ainn Mb.i MBn MWn MDn (S7-200), I:e/b O:e/b B3:e/b N7:e F8:e N9:e N10:e (archivos del SLC 500, elementos 0 a 255, bits de palabra 0 a 15). Los números de bit van de 0 a 7; las direcciones de palabra analógica del S7 son pares.",
    ),
    (
        Code::TypeAddressMismatch,
        "Las E/S digitales y los bits de marcas contienen BOOL; las E/S analógicas INT o DINT; MB contiene SINT, MW INT, MD DINT, REAL o TIME. Las estructuras (TIMER, COUNTER, PID) no pueden tener dirección.",
    ),
    (
        Code::BadInitialValue,
        "BOOL admite 0, 1, true o false; los enteros admiten números decimales (o con base 16#, 8#, 2#) dentro del rango del tipo; REAL admite un número; TIME admite milisegundos o un literal T#1m30s. Las estructuras no llevan valor inicial en tags.csv: su PRE y su ACC vienen de la instrucción (TON(t,5000,0)).",
    ),
    (
        Code::BadRetain,
        "`retain` está vacío (no se retiene), o es 0/1, true/false o yes/no.",
    ),
    (
        Code::ReservedType,
        "Ahora mismo no hay ningún tipo reservado (PID, que lo estuvo, está disponible). El código se conserva para que los informes antiguos mantengan su sentido.",
    ),
    (
        Code::PidParameter,
        "El campo `initial` de una variable PID es una lista de pares `MIEMBRO=valor` separados por `;` (por ejemplo `KP=5;KI=0.8;UPD=640;MAXS=10`). Cada miembro debe existir y poder escribirse, cada valor debe ser un número, y junto con los valores por defecto deben formar un lazo válido: UPD > 0 ms, ganancias y tiempos (KP KI KD KC TI TD) no negativos, MINS <= MAXS, 0 <= DB <= MAXS-MINS, 0 <= MINO <= MAXO <= 100 (%), DFN >= 0, FORM de 0 a 4, 11 o 12 (3 y 4 como los ejecutan los programas 004; FORM 3 y 11 con UPD >= 10 ms), sin NaN ni infinitos. El SLC 500 informa de estas mismas condiciones en ejecución como errores PID 11H 12H 13H 14H 23H 41H 51H 52H; Alba las informa al comprobar el proyecto, y en ejecución (ERRC, un fallo menor) cuando un programa escribe un valor así.",
    ),
    (
        Code::AlarmFile,
        "alarms.csv tiene la cabecera `id,tag,condition,severity,delay_ms,deadband,message` (puede seguir una octava columna `suppressed_by`) y una alarma por fila: un id único (letras, dígitos, `_`, `-`, `.`), una variable, miembro o dirección del programa, una condición (on, off, rising, falling, o > >= < <= == != y un número; las comparaciones solo para números), una severidad (1 a 1000, o low, medium, high, critical), un retardo a la conexión en ms (0 a 86400000; ninguno para rising/falling), una banda muerta ≥ 0 (para comparaciones), un mensaje y, opcionalmente, una variable BOOL que suprime la alarma mientras es verdadera. Vea docs/alarms.md.",
    ),
    (
        Code::ScreenFile,
        "Una pantalla del estudio (hmi/<pantalla>.json) no es válida: no es JSON, tiene un esquema que esta versión no lee, un tipo de elemento o una animación desconocidos, un elemento sin id o sin tamaño, una variable que el programa no tiene, una estructura donde hace falta un valor, un widget que escribe una entrada o una variable de solo lectura, o un rango cuyo máximo no supera su mínimo. El mensaje dice cuál, en su lugar del archivo; docs/file-formats.md describe el formato.",
    ),
    (
        Code::UnknownInstruction,
        "El nombre de la instrucción no está en el juego de instrucciones Ladder de Alba. Grupos: bits (XIC XIO OTE OTL OTU ONS OSR OSF), temporizadores (TON TOF RTO TP), contadores (CTU CTD RES), comparación (LIM EQU NEQ LES GRT LEQ GEQ MEQ), cálculo (ADD SUB MUL DIV MOD SQR NEG ABS XPY LN LOG CPT SCP), movimiento y lógica (MOV CLR AND OR XOR NOT), trigonometría (SIN COS TAN ASN ACS ATN DEG RAD), flujo del programa (JMP LBL AFI NOP).",
    ),
    (
        Code::IlSyntax,
        "Una línea AWL contiene una instrucción: un mnemónico y sus operandos separados por comas (`LD I0.0`, `MOVW +5, MW2`). Se aceptan las líneas `NETWORK n` y `TITLE =`, los comentarios `//` y `/* */` y el marco ORGANIZATION_BLOCK de las exportaciones de STEP 7-Micro/WIN.",
    ),
    (
        Code::UnknownMnemonic,
        "El mnemónico no está en el juego de instrucciones S7-200 de Alba. Lógica de bits: LD LDN A AN O ON NOT = S R EU ED; pila: ALD OLD LPS LRD LPP LDS; comparaciones: LDW= AW= OW= (y <> < > <= >=), LDD…/AD…/OD… para dobles palabras, LDR…/AR…/OR… para reales; cálculo: +I -I *I /I, +D -D *D /D, +R -R *R /R, INCW DECW INCD DECD; movimiento: MOVB MOVW MOVD MOVR; temporizadores: TON TONR TOF (TOFF); contadores: CTU CTD CTUD; flujo: FOR NEXT JMP LBL NOP.",
    ),
    (
        Code::LogicStack,
        "La lógica del S7-200 trabaja sobre una pila: LD, LDN, las comparaciones y LDS apilan un valor; A, O, =, los cuadros y los temporizadores usan la cima; ALD, OLD y LPP combinan o desapilan dos niveles; los contadores toman sus entradas de dos o tres niveles. Un segmento (y el código tras una etiqueta) empieza con la pila vacía: empiécelo con una instrucción de carga. La pila tiene 9 niveles: una décima carga tira el valor más antiguo, al que ya no puede llegar ninguna instrucción.",
    ),
    (
        Code::S7Timer,
        "En el S7-200 el número de temporizador fija su clase y su resolución: TONR usa T0–T31 y T64–T95, TON y TOF usan T32–T63 y T96–T255, y un número sirve a una sola clase de temporizador. Los contadores son C0–C255, un contador por número.",
    ),
    (
        Code::LoopStructure,
        "Cada FOR tiene su NEXT más adelante en el mismo programa, y los bucles se anidan como mucho a 8 niveles.",
    ),
    (
        Code::IlNotSupported,
        "Las subrutinas y rutinas de interrupción, las variables locales y las formas de byte INCB, DECB y LDB= … aún no están disponibles; use marcas M, palabras y un único programa principal.",
    ),
    (
        Code::StSyntax,
        "Un archivo de Texto Estructurado (`.st`) contiene POU de IEC 61131-3: `PROGRAM nombre … END_PROGRAM`, `FUNCTION`, `FUNCTION_BLOCK`, y bloques `TYPE … END_TYPE` y `VAR_GLOBAL`. Las sentencias terminan en `;`: asignaciones `x := e;`, llamadas `t1(IN := x, PT := T#5s);`, IF/ELSIF/ELSE/END_IF, CASE … OF … END_CASE, bucles FOR/WHILE/REPEAT, EXIT y RETURN. Los comentarios son `(* *)`, `/* */` y `//`. El mensaje dice qué se esperaba en el lugar indicado; vea docs/st.md.",
    ),
    (
        Code::StType,
        "El Texto Estructurado tiene tipos estrictos: los dos lados de un operador, y el valor y el destino de una asignación, tienen un mismo tipo, salvo que un valor se amplía implícitamente a un tipo mayor de su familia (SINT → INT → DINT → LINT, USINT → UINT → UDINT → ULINT, BYTE → WORD → DWORD → LWORD, REAL → LREAL, un entero a un REAL bastante ancho). Las condiciones son BOOL. El mensaje nombra los dos tipos; convierta con una función `*_TO_*` (`INT_TO_REAL(x)`).",
    ),
    (
        Code::StName,
        "Un nombre en ST es una variable de la POU, una variable de tags.csv (toda variable es global para todas las POU), una función o bloque de función estándar, o un miembro de una estructura o de una instancia de bloque de función (`t1.Q`). El mensaje sugiere el nombre conocido más parecido.",
    ),
    (
        Code::StNotSupported,
        "Alba traduce el ST a su única IR; unas pocas partes del lenguaje aún no tienen forma allí (STRING, LTIME, DATE y TIME_OF_DAY, arrays de estructuras o de bloques de función, punteros, llamadas recursivas: las FUNCTION y FUNCTION_BLOCK del usuario se expanden en línea donde se llaman). Se rechazan en su lugar en vez de compilarse a algo que se comporte distinto; docs/st.md las lista.",
    ),
    (
        Code::StDeclaration,
        "Una variable se declara una vez por POU; un ARRAY tiene límites constantes, con el inferior no mayor que el superior y como mucho 10 000 elementos; un valor inicial cabe en el tipo de la variable; una `VAR CONSTANT` no se escribe; EXIT está dentro de un bucle; la variable de un FOR es una variable entera de la POU.",
    ),
    (Code::DuplicateLabel, "Cada nombre de LBL aparece una vez por programa."),
    (
        Code::LabelNotFirst,
        "Una etiqueta marca el comienzo de un peldaño: escriba LBL(nombre) como primera instrucción del peldaño.",
    ),
    (
        Code::ConflictingPreset,
        "El PRE y el ACC literales de TON(t,pre,acc) son los valores iniciales de la estructura, así que todas las instrucciones sobre una misma variable deben dar los mismos (o `?`); del mismo modo, todo TON, TOF y RTO sobre un temporizador cuenta en una sola base de tiempo (TON(t,pre,acc,s); sin ella es ms), y TP solo sobre un temporizador en ms.",
    ),
    (
        Code::Expression,
        "CPT acepta + - * / MOD ** ^, paréntesis, comparaciones (= <> < > <= >=), AND OR XOR NOT, las funciones SQR SQRT ABS SIN COS TAN ASN ACS ATN ATAN2 LN LOG DEG RAD TRN FRD TOD ROUND, las de AuroraLD log10 logE log(a,b) Int signum cosh sinh tanh rnd(a,b) radians degrees, y PI y E.",
    ),
    (
        Code::NotYetSupported,
        "Ahora mismo no hay ninguna instrucción reservada (PID, que lo estuvo, está disponible; vea ladder.md y pid.md). El código se conserva para que los informes antiguos mantengan su sentido.",
    ),
    (
        Code::StimulusTarget,
        "Un estímulo fija entradas y variables internas por nombre, miembro o dirección; no se pueden fijar las salidas que escribe el programa, los bits de estado ni las variables del sistema.",
    ),
    (
        Code::TraceName,
        "--tags admite nombres de variables, miembros (Delay.ACC), direcciones (DO:2/0, %QX0.1) y variables del sistema (S:FS), separados por comas; un TIMER o COUNTER entero no es un valor: nombre un miembro.",
    ),
    (
        Code::NotOnBoard,
        "El firmware de un Arduino ejecuta el programa de control con REAL de 32 bits y sin coma flotante de 64 bits: se rechazan las variables LREAL y la aritmética LREAL, señalando la instrucción responsable. Use REAL, o ejecute el programa en el PC con la placa como E/S remota (modo controlador).",
    ),
    (
        Code::DoesNotFit,
        "El firmware construido necesita más flash o RAM de la que tiene la placa (el informe da ambas frente a los límites de la placa). Acorte el programa, use menos variables o elija una placa con más memoria (la Mega tiene 8 KiB de RAM y 248 KiB de flash).",
    ),
    (
        Code::Toolchain,
        "Para construir hacen falta gcc-avr, avr-libc y arduino-core-avr de Debian (./test.sh los instala); para cargar, avrdude y la placa en el puerto serie indicado. El mensaje da el error de la propia herramienta.",
    ),
    (
        Code::PnmlSyntax,
        "Un archivo .pnml es un documento XML (ISO/IEC 15909-2). El mensaje da el error XML en el lugar indicado: una etiqueta sin cerrar o que no corresponde, un atributo incorrecto, una entidad desconocida (solo se aceptan las cinco entidades predefinidas de XML y las referencias de carácter), texto fuera del elemento raíz. Los archivos de más de 16 MiB y los elementos anidados a más de 64 niveles se rechazan con E606.",
    ),
    (
        Code::PnmlStructure,
        "Alba lee un `<net id=\"..\" type=\"..\">` dentro de `<pnml>`, con páginas que contienen `<place id>`, `<transition id>` y `<arc id source target>`; todo nodo y arco necesita un `id` no vacío, y cada etiqueta (`name`, `initialMarking`, `inscription`) aparece como mucho una vez en un elemento. Vea docs/nets.md, sección pnml.",
    ),
    (
        Code::PnmlDuplicateId,
        "Los id de PNML son únicos en todo el documento: lugares, transiciones, arcos y páginas comparten un mismo espacio de nombres. Renombre uno de ellos (y los arcos que lo usan).",
    ),
    (
        Code::PnmlArc,
        "Un arco va de un lugar a una transición o de una transición a un lugar, y su `source` y su `target` nombran nodos de la red (un nodo de referencia representa al nodo al que se refiere). No se pueden unir dos lugares ni dos transiciones, y dos arcos no pueden unir el mismo par en el mismo sentido (dé en su lugar un peso al único arco).",
    ),
    (
        Code::PnmlNumber,
        "`<initialMarking><text>` es un número entero de 0 a 1000000, `<inscription><text>` (el peso de un arco) un entero de 1 a 1000000, el `<priority>` de Alba un entero (32 bits), las posiciones números decimales. Los valores negativos, fraccionarios y mayores se rechazan en vez de redondearse.",
    ),
    (
        Code::PnmlLimit,
        "Alba lee archivos PNML de hasta 16 MiB, con como mucho 1000000 elementos anidados a no más de 64 niveles, para que un archivo roto u hostil no agote la memoria ni la pila. Divida el modelo, o quite lo que no necesita (gráficos grandes, datos de otras herramientas).",
    ),
    (
        Code::PnmlAlba,
        "Alba guarda sus propios datos en `<toolspecific tool=\"alba\" version=\"1\">` sobre el elemento al que pertenecen: en la red `<mode>petri</mode>` o `<mode>normal</mode>` y `<widget id kind [tag] [x y]>rótulo</widget>` (kind button, display, plot o label); en un lugar `<tag>NOMBRE</tag>`, `<kind>` (state, counter, expression, variable, input, output, stop, end), `<prop name=\"..\">valor</prop>` y `<script>`; en una transición `<guard>EXPR</guard>`, `<priority>N</priority>`, `<kind>` (transition, condition, timer) y `<prop>`; en un arco `<kind>normal|inhibitor|read</kind>` (los arcos inhibidores y de lectura van de un lugar a una transición). Cada uno aparece como mucho una vez. Vea docs/nets.md.",
    ),
    (
        Code::PnmlIgnored,
        "Un elemento que Alba no conoce (la extensión de otra herramienta fuera de `<toolspecific>`, una etiqueta de otro tipo de red) se salta con este aviso, una vez por nombre de elemento; la red se carga. Los bloques `<toolspecific>` de otras herramientas no se ignoran: se conservan y se vuelven a escribir sin cambios.",
    ),
    (
        Code::NetMode,
        "El modo Petri tiene lugares y transiciones simples (con guardas y `<tag>`); las clases de las redes de estados (Timer, Condition, Counter, Expression, Variable, Input, Output, Stop, End) se ejecutan en modo normal (`<mode>normal</mode>`, docs/nets.md).",
    ),
    (
        Code::NetGuard,
        "Una `<guard>` es una expresión BOOL del lenguaje de expresiones de Alba para redes: nombres de variables y miembros, literales, `NOT`, `AND` (`&`), `OR` (`|`), `XOR`, paréntesis, comparaciones (= == <> != < > <= >=), aritmética (+ - * / : MOD % ** ^, con la precedencia de la fuente de las redes de estados) y sus funciones (cos, sqrt, rem, log...). Todo nombre debe ser una variable, un miembro, una dirección o una variable del sistema; un número solo no es una guarda: compárelo.",
    ),
    (
        Code::NetPlaceTag,
        "El `<tag>NOMBRE</tag>` de un lugar hace que la red escriba la variable NOMBRE: un BOOL, verdadero mientras el lugar está marcado, o, cuando el lugar tiene un `value` (un número), una variable numérica que guarda esa constante mientras el lugar está marcado y 0 después. NOMBRE debe ser una variable o un miembro de esa clase que el programa pueda escribir: no una entrada, un bit de estado, una variable del sistema ni un marcado.",
    ),
    (
        Code::NetTagClash,
        "El marcado del lugar P de la red N (archivo N.pnml) es la variable DINT `N.P`; ninguna variable de tags.csv, ningún lugar de otra red y ningún miembro de una variable TIMER, COUNTER o PID llamada N (`N.DN`) puede tener ese nombre.",
    ),
    (
        Code::NetRange,
        "Los marcados son variables DINT: un marcado inicial o un peso de arco (los arcos entre un lugar y una transición, sumados) debe ser como mucho 2147483647.",
    ),
    (
        Code::NetArc,
        "Los arcos inhibidores y de lectura (de prueba) van de un lugar a una transición; de una transición a un lugar solo los arcos normales producen marcas.",
    ),
    (
        Code::NetElement,
        "En una red en modo normal (docs/nets.md, \"Normal mode\") cada elemento contiene como mucho una marca y la pasa: los arcos son simples (sin arcos inhibidores ni de lectura) y pesan 1; una Condition necesita una `<guard>`; un Timer necesita `<prop name=\"delay\">` (milisegundos o T#5s); un Counter admite `load` (un DINT) y `direction` (up o down); un Input `source`; un Output `target` y `source`; una Variable `mode` (Assignment, Variable, WriteToMyVariable, WriteToTarget, DefineTarget, ResetTargetValue), `source`, `target`, `value` e `initial` según lo pida su modo; las demás clases no admiten propiedades.",
    ),
    (
        Code::NetScript,
        "Un elemento Expression (modo normal) ejecuta su `<script>` en cada ciclo en que tiene la marca: secciones `define{a, b}` (nombres de las variables que usa), `constant{k = 2.5}` (o `const{}`) y `function{...}` con sentencias separadas por `;` o saltos de línea, cada una `destino = expresión` o una expresión sola cuyo valor va a la variable propia del elemento `<red>.<id>.value` (REAL); `//` empieza un comentario. Las expresiones son el lenguaje de expresiones de Alba para redes (números y variables, + - * / : MOD % ** ^ con la precedencia de la fuente, paréntesis, y las funciones de la fuente cos, cosh, arcos, sin, sinh, arcsin, tan, tanh, arctan, sqrt, rem, root, pow, exp, abs, log, round, truncate, floor, ceiling, sign); los destinos son variables numéricas que un programa puede escribir.",
    ),
    (
        Code::SfcSyntax,
        "Un archivo .sfc es el SFC textual de IEC 61131-3: `INITIAL_STEP nombre: acciones END_STEP`, `STEP nombre: acciones END_STEP`, donde una acción es `Variable(Q)` o `Variable(Q, T#5s)` terminada en `;` (Q uno de N S R L D P P1 P0 SD DS SL), y `TRANSITION [nombre] [(PRIORITY := n)] FROM etapa TO etapa := condición; END_TRANSITION` (listas de etapas entre paréntesis para la divergencia y la convergencia simultáneas). Los comentarios son `(* ... *)` y `//`. Vea docs/nets.md, SFC.",
    ),
    (
        Code::SfcStructure,
        "Un SFC tiene exactamente un INITIAL_STEP, nombres de etapa únicos, transiciones entre etapas declaradas, un tiempo en los calificadores temporizados (L D SD DS SL) y ninguno en los demás.",
    ),
    (
        Code::SfcAction,
        "Una acción es una variable BOOL (o un miembro) que un programa puede escribir: no una entrada, un bit de estado ni una variable del sistema.",
    ),
    (
        Code::ImportFailed,
        "`alba import` lee archivos `.ld` de LDmicro, XML PLCopen TC6 v2.01 y exportaciones `.L5X` de Studio 5000 (el contenido decide el formato, si no la extensión; `--format ldmicro|plcopen|l5x` lo fuerza). El mensaje nombra el lugar de la entrada (`archivo:línea:col`) que está mal formado o que Alba no puede convertir en absoluto; las construcciones que puede omitir se listan como rechazadas en el informe, y se importa el resto. La carpeta de salida debe ser nueva o estar vacía salvo con `--force`. Cuando una importación falla no se escribe nada. Vea docs/interchange.md.",
    ),
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
    // what the ST parser expected, and what it found
    ("the end of the file", "el final del archivo"),
    ("a string", "una cadena"),
    ("a name", "un nombre"),
    ("an expression", "una expresión"),
    ("an operator, `;` or `)`", "un operador, `;` o `)`"),
    (
        "`:=` or `(` (an assignment or a call)",
        "`:=` o `(` (una asignación o una llamada)",
    ),
    (
        "a CASE label, `ELSE` or `END_CASE`",
        "una etiqueta de CASE, `ELSE` o `END_CASE`",
    ),
    ("a statement", "una sentencia"),
    // the numbers of a PNML file
    ("an initial marking", "un marcado inicial"),
    ("a priority", "una prioridad"),
    ("an arc weight", "el peso de un arco"),
    // why the nets analysis's symbolic engine stopped
    ("node budget", "presupuesto de nodos"),
    ("memory budget", "presupuesto de memoria"),
    ("time budget", "presupuesto de tiempo"),
    ("cancelled", "cancelado"),
    ("a place count exceeds 2^32-1", "un lugar supera 2^32-1 marcas"),
    ("the other order completed first", "el otro orden terminó antes"),
    // the facts the symbolic engine may leave undecided
    ("dead transitions", "las transiciones muertas"),
    ("deadlocks", "los bloqueos"),
    ("a trace to a deadlock", "una traza hasta un bloqueo"),
    ("liveness", "la vivacidad"),
    ("reversibility", "la reversibilidad"),
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
    if let Some(n) = v.strip_prefix("the number ") {
        return format!("el número {n}");
    }
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

/// `message` of `code` in Spanish by its template (else by a [`SHARED`] one),
/// if one matches: the most
/// specific (most literal text) when several do, so that `{} does not fit {}`
/// does not take what `{} does not fit {} `{}` ({} to {})` says better.
pub fn message(code: Code, message: &str) -> Option<String> {
    best(
        MESSAGES
            .iter()
            .filter(|(c, _, _)| *c == code)
            .map(|(_, en, es)| (*en, *es)),
        message,
    )
    .or_else(|| best(SHARED.iter().copied(), message))
}

/// The Spanish of `text` by the most specific of `templates` that matches.
fn best<'a>(templates: impl Iterator<Item = (&'a str, &'a str)>, text: &str) -> Option<String> {
    templates
        .filter_map(|(en, es)| crate::lang::match_template(en, text).map(|v| (en.len() - 2 * v.len(), es, v)))
        .max_by_key(|(literal, _, _)| *literal)
        .map(|(_, es, v)| fill_values(es, &v))
}

/// The API's error replies (`{"error": …}`) in Spanish, for a request whose
/// `Accept-Language` asks for it: (English pattern, Spanish), as [`MESSAGES`].
/// An error that echoes a diagnostic's message (`unknown tag `X``) takes that
/// message's template instead ([`error`]).
pub const ERRORS: &[(&str, &str)] = &[
    // 401, 403, 429: sessions and roles
    (
        "log in first (POST /api/login)",
        "inicie sesión primero (POST /api/login)",
    ),
    (
        "unknown user or wrong password",
        "usuario desconocido o contraseña incorrecta",
    ),
    (
        "too many failed logins: try again in {} s",
        "demasiados inicios de sesión fallidos: vuelva a intentarlo en {0} s",
    ),
    (
        "this needs the role {}; you are {}",
        "esto necesita el rol {0}; usted es {1}",
    ),
    (
        "user {} is a {}: {} needs the {} role (users.toml)",
        "el usuario {0} es {1}: {2} necesita el rol {3} (users.toml)",
    ),
    (
        "this project has no users, so only clients on this computer (loopback) are served; add users with `alba user add`",
        "este proyecto no tiene usuarios, así que solo se atiende a los clientes de este ordenador (loopback); añada usuarios con `alba user add`",
    ),
    // 404
    ("no such endpoint", "no existe ese punto de acceso de la API"),
    (
        "no program `{}` in this project",
        "no hay ningún programa `{0}` en este proyecto",
    ),
    ("the project has no tags.csv", "el proyecto no tiene tags.csv"),
    ("no net `{}` in the project", "no hay ninguna red `{0}` en el proyecto"),
    ("no hardware job `{}`", "no hay ningún trabajo de hardware `{0}`"),
    (
        "this server has no hardware service",
        "este servidor no tiene servicio de hardware",
    ),
    (
        "this server has no verification service",
        "este servidor no tiene servicio de verificación",
    ),
    (
        "this project keeps no alarm log (no alarms.csv)",
        "este proyecto no lleva registro de alarmas (no hay alarms.csv)",
    ),
    (
        "no alarm `{}` (the project has no alarms.csv)",
        "no hay ninguna alarma `{0}` (el proyecto no tiene alarms.csv)",
    ),
    ("no alarm `{}`", "no hay ninguna alarma `{0}`"),
    ("`{}` is not forced", "`{0}` no está forzada"),
    ("no history for `{}`", "no hay histórico de `{0}`"),
    (
        "history is off for this project (`[history] enabled = false` in alba.toml)",
        "el histórico está desactivado en este proyecto (`[history] enabled = false` en alba.toml)",
    ),
    (
        "this server keeps no audit trail",
        "este servidor no lleva registro de auditoría",
    ),
    // 409, 503: the runtime and the board
    ("the runtime has stopped", "el motor se ha detenido"),
    (
        "the runtime is running: stop it before stepping one scan",
        "el motor está en marcha: deténgalo antes de avanzar un ciclo",
    ),
    (
        "the runtime is faulted ({}): run it again before stepping",
        "el motor está en fallo ({0}): póngalo en marcha de nuevo antes de avanzar",
    ),
    (
        "the runtime is busy: {} requests wait for the next scan; try again",
        "el motor está ocupado: {0} peticiones esperan el próximo ciclo; vuelva a intentarlo",
    ),
    (
        "the board on {} is attached ({}): detach it first",
        "la placa de {0} está conectada ({1}): desconéctela primero",
    ),
    (
        "{} is the project's own I/O already (alba run --io {})",
        "{0} ya es la E/S del propio proyecto (alba run --io {1})",
    ),
    ("no board is attached", "no hay ninguna placa conectada"),
    (
        "the board runs the program ({}): forces, online edits and stop are done on a board by exporting and uploading again; writes work",
        "la placa ejecuta el programa ({0}): los forzados, las ediciones en línea y la parada se hacen en una placa exportando y cargando de nuevo; las escrituras sí funcionan",
    ),
    (
        "an analysis of this project is running: wait for it to end, or cancel it",
        "hay un análisis de este proyecto en curso: espere a que termine, o cancélelo",
    ),
    (
        "a verification, test run or analysis of this project is running: wait for it to end",
        "hay una verificación, prueba o análisis de este proyecto en curso: espere a que termine",
    ),
    (
        "the request took longer than {} s: try again, or raise [http] request_timeout_s",
        "la petición tardó más de {0} s: vuelva a intentarlo, o aumente [http] request_timeout_s",
    ),
    // 422: program edits and values
    ("1 error", "1 error"),
    ("{} errors", "{0} errores"),
    ("cannot save {}: {}", "no se puede guardar {0}: {1}"),
    ("saved, but not applied: {}", "guardado, pero no aplicado: {0}"),
    (
        "`{}` is a timer's preset: it cannot be negative",
        "`{0}` es la preselección de un temporizador: no puede ser negativa",
    ),
    ("`{}` is a structure, not I/O", "`{0}` es una estructura, no E/S"),
    (
        "`{}` is not an input or an output: only I/O can be forced (write internal tags instead)",
        "`{0}` no es una entrada ni una salida: solo se puede forzar la E/S (escriba en su lugar las variables internas)",
    ),
    (
        "`{}`: expected an integer for a {}, got {}",
        "`{0}`: se esperaba un entero para un {1}; llegó {2}",
    ),
    (
        "`{}`: {} is out of range for {} ({} to {})",
        "`{0}`: {1} está fuera del rango de {2} ({3} a {4})",
    ),
    (
        "`{}`: expected true, false, 0 or 1 for a BOOL, got {}",
        "`{0}`: se esperaba true, false, 0 o 1 para un BOOL; llegó {1}",
    ),
    (
        "`{}`: expected a number for a {}, got {}",
        "`{0}`: se esperaba un número para un {1}; llegó {2}",
    ),
    (
        "`{}`: {} is out of range for REAL",
        "`{0}`: {1} está fuera del rango de REAL",
    ),
    (
        "`{}`: a {} is a structure: write one of its members",
        "`{0}`: un {1} es una estructura: escriba uno de sus miembros",
    ),
    (
        "the running program has no marking tag `{}`: save the net and apply it online first",
        "el programa en marcha no tiene la variable de marcado `{0}`: guarde la red y aplíquela en línea primero",
    ),
    // 400, 413, 415, 421: the request itself
    (
        "the request body is too large",
        "el cuerpo de la petición es demasiado grande",
    ),
    ("the body needs a `{}` field", "el cuerpo necesita un campo `{0}`"),
    (
        "`{}` must be an integer, got `{}`",
        "`{0}` debe ser un entero; llegó `{1}`",
    ),
    ("`{}` must be a string", "`{0}` debe ser una cadena"),
    ("the query needs `{}`", "la consulta necesita `{0}`"),
    ("{} is not UTF-8 text: {}", "{0} no es texto UTF-8: {1}"),
    ("malformed JSON body: {}", "cuerpo JSON mal formado: {0}"),
    (
        "malformed JSON body: Failed to parse the request body as JSON: {}",
        "cuerpo JSON mal formado: no se pudo leer como JSON: {0}",
    ),
    (
        "malformed JSON body: Failed to deserialize the JSON body into the target type: {}",
        "cuerpo JSON mal formado: no tiene la forma que espera la petición: {0}",
    ),
    (
        "Failed to parse the request body as JSON: {}",
        "no se pudo leer el cuerpo de la petición como JSON: {0}",
    ),
    (
        "Failed to deserialize the JSON body into the target type: {}",
        "el cuerpo JSON no tiene la forma que espera la petición: {0}",
    ),
    (
        "Expected request with `Content-Type: application/json`",
        "se esperaba una petición con `Content-Type: application/json`",
    ),
    (
        "the request has no `Host` header",
        "la petición no tiene cabecera `Host`",
    ),
    (
        "a {} request must be sent as `Content-Type: application/json` ({})",
        "una petición {0} debe enviarse como `Content-Type: application/json` ({1})",
    ),
    (
        "`Host: {}` is not a name of this server: add it to `[http] allowed_hosts` in alba.toml to reach the studio by that name",
        "`Host: {0}` no es un nombre de este servidor: añádalo a `[http] allowed_hosts` en alba.toml para llegar al estudio con ese nombre",
    ),
    (
        "requests from `{}` are refused: only the studio's own origin and `[http] allowed_origins` may change anything or open the WebSocket",
        "se rechazan las peticiones de `{0}`: solo el origen del propio estudio y `[http] allowed_origins` pueden cambiar algo o abrir el WebSocket",
    ),
    (
        "the WebSocket handshake needs an `Origin` header",
        "el saludo del WebSocket necesita una cabecera `Origin`",
    ),
];

/// An API error reply in Spanish: by [`ERRORS`], else by the template of
/// any diagnostic message it echoes ([`MESSAGES`]); `None` when neither has it
/// (the server then answers in English).
pub fn error(text: &str) -> Option<String> {
    best(ERRORS.iter().copied(), text)
        .or_else(|| best(SHARED.iter().copied(), text))
        .or_else(|| best(MESSAGES.iter().map(|(_, en, es)| (*en, *es)), text))
}

/// The language's texts that `GET /api/domain` and `/api/instructions` give the studio
/// (instruction groups, titles, docs and operand labels, operand kinds, screen elements
/// and the designer's parameter help), English → Spanish; the server words the reply
/// by it for a Spanish request. `the_domain_speaks_spanish` (alba-server) fails when a
/// text has no entry, or an entry no text.
pub const DOMAIN: &[(&str, &str)] = &[
    ("Bit", "Bit"),
    ("Timer", "Temporizador"),
    ("Counter", "Contador"),
    ("Compare", "Comparación"),
    ("Math", "Matemáticas"),
    ("Move/Logic", "Mover/Lógica"),
    ("Trig", "Trigonometría"),
    ("Flow", "Flujo"),
    ("Special", "Especial"),
    ("a BOOL to read", "un BOOL que leer"),
    ("a label (LBL)", "una etiqueta (LBL)"),
    ("an expression (CPT)", "una expresión (CPT)"),
    ("Examine If Closed", "Examinar si cerrado"),
    (
        "examine if closed: passes the rung when the bit is 1",
        "examinar si cerrado: deja pasar el peldaño cuando el bit es 1",
    ),
    ("Examine If Open", "Examinar si abierto"),
    (
        "examine if open: passes the rung when the bit is 0",
        "examinar si abierto: deja pasar el peldaño cuando el bit es 0",
    ),
    ("Output Energize", "Activar salida"),
    ("output energise: bit = rung", "activar salida: bit = peldaño"),
    ("Output Latch", "Enclavar salida"),
    (
        "output latch: sets the bit while the rung is true",
        "enclavar salida: pone el bit a 1 mientras el peldaño es verdadero",
    ),
    ("Output Unlatch", "Desenclavar salida"),
    (
        "output unlatch: clears the bit while the rung is true",
        "desenclavar salida: pone el bit a 0 mientras el peldaño es verdadero",
    ),
    ("One Shot", "Flanco único"),
    (
        "one shot: passes one scan on a rising rung (storage bit)",
        "flanco único: deja pasar un ciclo cuando el peldaño sube (bit de memoria)",
    ),
    ("Storage Bit", "Bit de memoria"),
    ("One Shot Rising", "Flanco ascendente"),
    (
        "one shot rising: output bit true for one scan on a rising rung",
        "flanco ascendente: bit de salida a 1 durante un ciclo cuando el peldaño sube",
    ),
    ("Output Bit", "Bit de salida"),
    ("One Shot Falling", "Flanco descendente"),
    (
        "one shot falling: output bit true for one scan on a falling rung",
        "flanco descendente: bit de salida a 1 durante un ciclo cuando el peldaño baja",
    ),
    ("Timer On Delay", "Temporizador a la conexión"),
    (
        "on-delay timer (ms; a 4th operand gives another time base: cs ds s min)",
        "temporizador a la conexión (ms; un 4.º operando da otra base de tiempo: cs ds s min)",
    ),
    ("Preset", "Preselección"),
    ("Accum", "Acumulado"),
    ("Timer Off Delay", "Temporizador a la desconexión"),
    (
        "off-delay timer (ms; a 4th operand gives another time base: cs ds s min)",
        "temporizador a la desconexión (ms; un 4.º operando da otra base de tiempo: cs ds s min)",
    ),
    ("Retentive Timer On", "Temporizador retentivo a la conexión"),
    (
        "retentive on-delay timer (ms; a 4th operand gives another time base: cs ds s min), cleared by RES",
        "temporizador retentivo a la conexión (ms; un 4.º operando da otra base de tiempo: cs ds s min), se borra con RES",
    ),
    ("Pulse Timer", "Temporizador de impulso"),
    (
        "pulse timer: DN for PRE ms from a rising rung",
        "temporizador de impulso: DN durante PRE ms desde que el peldaño sube",
    ),
    ("Count Up", "Contar ascendente"),
    (
        "count up on a rising rung",
        "cuenta hacia arriba cuando el peldaño sube",
    ),
    ("Count Down", "Contar descendente"),
    (
        "count down on a rising rung",
        "cuenta hacia abajo cuando el peldaño sube",
    ),
    ("Reset", "Restablecer"),
    ("reset a timer or counter", "restablece un temporizador o un contador"),
    ("Structure", "Estructura"),
    ("Limit Test", "Prueba de límites"),
    (
        "limit test: low <= test <= high (wraps when low > high)",
        "prueba de límites: bajo <= prueba <= alto (fuera del intervalo cuando bajo > alto)",
    ),
    ("Low Limit", "Límite bajo"),
    ("Test", "Prueba"),
    ("High Limit", "Límite alto"),
    ("Equal", "Igual"),
    ("equal", "igual"),
    ("Source A", "Origen A"),
    ("Source B", "Origen B"),
    ("Not Equal", "Distinto"),
    ("not equal", "distinto"),
    ("Less Than", "Menor que"),
    ("less than", "menor que"),
    ("Greater Than", "Mayor que"),
    ("greater than", "mayor que"),
    ("Less Than or Equal", "Menor o igual que"),
    ("less than or equal", "menor o igual que"),
    ("Greater Than or Equal", "Mayor o igual que"),
    ("greater than or equal", "mayor o igual que"),
    ("Masked Equal", "Igual con máscara"),
    (
        "masked equal: (src AND mask) = (compare AND mask)",
        "igual con máscara: (origen AND máscara) = (comparación AND máscara)",
    ),
    ("Source", "Origen"),
    ("Mask", "Máscara"),
    ("Add", "Sumar"),
    ("dest = a + b", "destino = a + b"),
    ("Dest", "Destino"),
    ("Subtract", "Restar"),
    ("dest = a - b", "destino = a - b"),
    ("Multiply", "Multiplicar"),
    ("dest = a * b", "destino = a * b"),
    ("Divide", "Dividir"),
    ("dest = a / b", "destino = a / b"),
    ("Modulo", "Módulo"),
    (
        "dest = a modulo b (sign of a)",
        "destino = a módulo b (con el signo de a)",
    ),
    ("Square Root", "Raíz cuadrada"),
    ("dest = square root of src", "destino = raíz cuadrada del origen"),
    ("Negate", "Cambiar de signo"),
    ("dest = -src", "destino = -origen"),
    ("Absolute Value", "Valor absoluto"),
    ("dest = |src|", "destino = |origen|"),
    ("X to the Power of Y", "X elevado a Y"),
    ("dest = a to the power b", "destino = a elevado a b"),
    ("Natural Log", "Logaritmo natural"),
    (
        "dest = natural logarithm of src",
        "destino = logaritmo natural del origen",
    ),
    ("Log Base 10", "Logaritmo en base 10"),
    (
        "dest = base-10 logarithm of src",
        "destino = logaritmo en base 10 del origen",
    ),
    ("Compute", "Calcular"),
    ("compute: dest = expression", "calcular: destino = expresión"),
    ("Expression", "Expresión"),
    ("Scale with Parameters", "Escalar con parámetros"),
    (
        "scale with parameters: (in-inMin)*((scMax-scMin)/(inMax-inMin))+scMin",
        "escalar con parámetros: (in-inMin)*((scMax-scMin)/(inMax-inMin))+scMin",
    ),
    ("Input", "Entrada"),
    ("Input Min", "Entrada mín."),
    ("Input Max", "Entrada máx."),
    ("Scaled Min", "Escalado mín."),
    ("Scaled Max", "Escalado máx."),
    ("Output", "Salida"),
    ("Move", "Mover"),
    ("dest = src", "destino = origen"),
    ("Clear", "Borrar"),
    ("dest = 0", "destino = 0"),
    ("Bitwise AND", "AND bit a bit"),
    ("bitwise and", "y bit a bit"),
    ("Bitwise OR", "OR bit a bit"),
    ("bitwise or", "o bit a bit"),
    ("Bitwise XOR", "XOR bit a bit"),
    ("bitwise exclusive or", "o exclusivo bit a bit"),
    ("Bitwise NOT", "NOT bit a bit"),
    ("bitwise complement", "complemento bit a bit"),
    ("Sine", "Seno"),
    ("sine (radians)", "seno (radianes)"),
    ("Cosine", "Coseno"),
    ("cosine (radians)", "coseno (radianes)"),
    ("Tangent", "Tangente"),
    ("tangent (radians)", "tangente (radianes)"),
    ("Arc Sine", "Arcoseno"),
    ("arc sine (radians)", "arcoseno (radianes)"),
    ("Arc Cosine", "Arcocoseno"),
    ("arc cosine (radians)", "arcocoseno (radianes)"),
    ("Arc Tangent", "Arcotangente"),
    ("arc tangent (radians)", "arcotangente (radianes)"),
    ("Radians to Degrees", "Radianes a grados"),
    ("radians to degrees", "radianes a grados"),
    ("Degrees to Radians", "Grados a radianes"),
    ("degrees to radians", "grados a radianes"),
    ("Jump to Label", "Saltar a etiqueta"),
    (
        "jump to the rung with LBL(label) while the rung is true",
        "salta al peldaño con LBL(etiqueta) mientras el peldaño es verdadero",
    ),
    ("Label", "Etiqueta"),
    (
        "label: the target of JMP, first instruction of its rung",
        "etiqueta: el destino de JMP, primera instrucción de su peldaño",
    ),
    ("Always False", "Siempre falso"),
    ("always false", "siempre falso"),
    ("No Operation", "Sin operación"),
    ("no operation", "sin operación"),
    ("PID Loop", "Lazo PID"),
    (
        "PID loop: drives the control output from the process value (docs/pid.md)",
        "lazo PID: mueve la salida de control según el valor del proceso (docs/pid.md)",
    ),
    ("PID", "PID"),
    ("Process Var", "Variable de proceso"),
    ("Control Var", "Variable de control"),
    ("a static or live text", "un texto fijo o en vivo"),
    (
        "an input box that writes a number or a BOOL",
        "una casilla de entrada que escribe un número o un BOOL",
    ),
    (
        "an output box showing a value",
        "una casilla de salida que muestra un valor",
    ),
    ("a rectangle", "un rectángulo"),
    ("a circle or ellipse", "un círculo o una elipse"),
    ("a momentary push button", "un pulsador"),
    ("a latching switch", "un interruptor con enclavamiento"),
    ("a line", "una línea"),
    ("a polygon", "un polígono"),
    ("a slider that writes a number", "un deslizador que escribe un número"),
    ("an indicator lamp", "un piloto"),
    ("an arc", "un arco"),
    ("a wind turbine", "un aerogenerador"),
    ("a fan", "un ventilador"),
    ("a cooling tower", "una torre de refrigeración"),
    ("a PLC", "un autómata"),
    ("a clock", "un reloj"),
    ("an image", "una imagen"),
    ("a bottle", "una botella"),
    ("a motor", "un motor"),
    ("a pump", "una bomba"),
    ("a tank or silo", "un depósito o silo"),
    ("a pipe", "una tubería"),
    ("a valve", "una válvula"),
    ("a building", "un edificio"),
    ("a transmission tower", "una torre de alta tensión"),
    ("a safety sign", "una señal de seguridad"),
    ("a bar or circular meter", "un medidor de barra o circular"),
    ("an alarm indicator", "un indicador de alarma"),
    ("a trend graph", "un gráfico de tendencias"),
    (
        "a PID loop's faceplate (SP, PV, CV; opens the full faceplate)",
        "el panel de un lazo PID (SP, PV, CV; abre el panel completo)",
    ),
    (
        "the text shown (when no tag is shown)",
        "el texto que se muestra (cuando no se muestra una variable)",
    ),
    ("the font size", "el tamaño de letra"),
    ("the colour of its body", "el color de su cuerpo"),
    ("the figures after the point", "las cifras decimales"),
    (
        "the unit shown after the value",
        "la unidad que se muestra tras el valor",
    ),
    ("the colour of its outline", "el color de su contorno"),
    ("the width of its outline", "el grosor de su contorno"),
    (
        "its vertices [x, y] in its box (up to 200)",
        "sus vértices [x, y] en su recuadro (hasta 200)",
    ),
    (
        "where it starts, clockwise from 12 o'clock (default -90)",
        "dónde empieza, en sentido horario desde las 12 (por defecto -90)",
    ),
    ("where it ends (default 90)", "dónde termina (por defecto 90)"),
    (
        "open, closed by its chord, or a pie closed through its centre",
        "abierto, cerrado por su cuerda o un sector cerrado por su centro",
    ),
    (
        "a toggle lever, a rocker or a rotary selector",
        "una palanca, un basculante o un selector giratorio",
    ),
    (
        "drawn on its tower (default yes)",
        "dibujado sobre su torre (por defecto sí)",
    ),
    (
        "drawn in its casing (default yes)",
        "dibujado en su carcasa (por defecto sí)",
    ),
    (
        "its RUN and I/O lamps blink while this BOOL is on",
        "sus pilotos RUN y E/S parpadean mientras este BOOL está activo",
    ),
    (
        "the image: assets/<name> of the project",
        "la imagen: assets/<nombre> del proyecto",
    ),
    (
        "its size in percent of the box (default: fitted)",
        "su tamaño en porcentaje del recuadro (por defecto: ajustado)",
    ),
    (
        "its cap is on while this BOOL is on",
        "tiene el tapón puesto mientras este BOOL está activo",
    ),
    (
        "an upright tank, a silo with its cone, or a lying tank",
        "un depósito vertical, un silo con su cono o un depósito horizontal",
    ),
    (
        "straight, an elbow, a tee or a cross (turned by the element's rotation)",
        "recta, un codo, una te o una cruz (girada con la rotación del elemento)",
    ),
    (
        "a gate, a ball or a butterfly valve",
        "una válvula de compuerta, de bola o de mariposa",
    ),
    (
        "its windows are lit while this BOOL is on",
        "sus ventanas están iluminadas mientras este BOOL está activo",
    ),
    ("the sign shown", "la señal que se muestra"),
    ("a bar or a circular gauge", "una barra o un indicador circular"),
    ("the bottom of its scale", "el mínimo de su escala"),
    ("the top of its scale", "el máximo de su escala"),
    (
        "the seconds it shows up to now (default 120)",
        "los segundos que muestra hasta ahora (por defecto 120)",
    ),
    (
        "up to 3 pens, each a tag and its colour (the element's `tag` when none)",
        "hasta 3 plumas, cada una una variable y su color (la `tag` del elemento si no hay ninguna)",
    ),
    (
        "active while the tag is on (off: while it is off, or outside min–max)",
        "activa mientras la variable está activa (off: mientras está inactiva, o fuera de min–max)",
    ),
    (
        "a number tag: active from this value (digital when neither min nor max is set)",
        "una variable numérica: activa desde este valor (digital si no se da ni min ni max)",
    ),
    (
        "a number tag: active up to this value",
        "una variable numérica: activa hasta este valor",
    ),
    (
        "time shown in each blink (default 500)",
        "tiempo visible en cada parpadeo (por defecto 500)",
    ),
    (
        "time hidden in each blink (default 500)",
        "tiempo oculto en cada parpadeo (por defecto 500)",
    ),
    (
        "the whole blink, shown and hidden for half each (on_ms and off_ms win)",
        "el parpadeo entero, visible y oculto la mitad cada uno (on_ms y off_ms tienen prioridad)",
    ),
    (
        "the tag's value at the start of the range",
        "el valor de la variable al principio del intervalo",
    ),
    (
        "the tag's value at the end of the range",
        "el valor de la variable al final del intervalo",
    ),
    (
        "the move right at max (negative: left)",
        "el desplazamiento a la derecha en max (negativo: a la izquierda)",
    ),
    (
        "the move down at max (negative: up)",
        "el desplazamiento hacia abajo en max (negativo: hacia arriba)",
    ),
    ("the angle at min (default 0)", "el ángulo en min (por defecto 0)"),
    (
        "the angle at max, clockwise (default 360; a meter's needle 270)",
        "el ángulo en max, en sentido horario (por defecto 360; la aguja de un medidor 270)",
    ),
    (
        "spin at this speed while active instead (negative: anticlockwise)",
        "en su lugar, gira a esta velocidad mientras está activa (negativo: en sentido antihorario)",
    ),
    (
        "the anchor point's x in the element's box (default its centre, or the rotor's hub)",
        "la x del punto de anclaje en el recuadro del elemento (por defecto su centro, o el buje del rotor)",
    ),
    (
        "the anchor point's y in the element's box",
        "la y del punto de anclaje en el recuadro del elemento",
    ),
    (
        "the colour while the tag is on",
        "el color mientras la variable está activa",
    ),
    (
        "the colour while the tag is off",
        "el color mientras la variable está inactiva",
    ),
    (
        "a number tag: up to 4 colours, each from its value up",
        "una variable numérica: hasta 4 colores, cada uno desde su valor hacia arriba",
    ),
    ("the way the level rises", "el sentido en que sube el nivel"),
    ("the colour of the level", "el color del nivel"),
    ("Time base", "Base de tiempo"),
    (
        "a time base: ms, cs, ds, s or min (ms when left out)",
        "una base de tiempo: ms, cs, ds, s o min (ms si se omite)",
    ),
];

/// `text` of the domain in Spanish ([`DOMAIN`], else [`VALUES`]: the operand
/// kinds are the noun phrases messages use).
pub fn domain_text(text: &str) -> Option<&'static str> {
    DOMAIN
        .iter()
        .chain(VALUES)
        .find(|(en, _)| *en == text)
        .map(|(_, es)| *es)
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
    fn every_code_is_explained_in_spanish() {
        let missing: Vec<String> = Code::ALL
            .iter()
            .filter(|c| explanation(**c).is_none_or(|e| e.trim().is_empty()))
            .map(|c| c.to_string())
            .collect();
        assert!(missing.is_empty(), "codes without a Spanish explanation: {missing:?}");
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
        for (en, es) in PHRASES.iter().chain(ERRORS).chain(SHARED) {
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
        // The most specific template wins, wherever it is listed.
        assert_eq!(
            message(
                Code::StType,
                "cannot assign a REAL to `x`, an INT; convert it (for example REAL_TO_INT)"
            )
            .as_deref(),
            Some("no se puede asignar un REAL a `x`, un INT; conviértalo (por ejemplo REAL_TO_INT)")
        );
        // A template belongs to its code; the shared readers' messages to any.
        assert_eq!(message(Code::Syntax, "tags.csv is empty"), None);
        assert_eq!(
            message(Code::StimulusTarget, "unknown tag `Strat`").as_deref(),
            Some("variable desconocida `Strat`")
        );
        assert_eq!(
            error("this needs the role engineer; you are viewer").as_deref(),
            Some("esto necesita el rol engineer; usted es viewer")
        );
        // an error that echoes a diagnostic takes its template
        assert_eq!(
            error("unknown tag `Nope`").as_deref(),
            Some("variable desconocida `Nope`")
        );
        assert_eq!(error("3 errors").as_deref(), Some("3 errores"));
        assert_eq!(error("something new"), None);
        assert_eq!(
            phrase("did you mean `Start`?").as_deref(),
            Some("¿quiso decir `Start`?")
        );
    }
}
