/*
 * KRL.g4 -- grammar of the KUKA Robot Language (KSS 8.x), recovered from real code.
 *
 * This grammar starts deliberately restrictive: it encodes the documented syntax of
 * ../shared/docs/krl-reference.md sections 1-6.1 and, wherever the reference is vague,
 * takes the most restrictive reading.  It grows one validated construct per commit
 * (see grammar/CHANGES.md); `krl growth` replays its git history over a corpus.
 *
 * Conventions
 *  - One combined grammar, case-insensitive, line-oriented: NEWLINE ends a statement.
 *  - ';' comments and ';FOLD' / ';ENDFOLD' lines are on the hidden channel.
 *  - The start rule is `module` in every version (the growth replay relies on it).
 *  - The parse front end appends a final newline to a file that lacks one.
 */
grammar KRL;

options { caseInsensitive = true; }

// ======================================================================== parser

// A .src, .sub or .dat file (reference 2.1, 2.2, 2.5).
// Blank and comment lines are allowed everywhere (1.4), also before the header lines.
module
    : NEWLINE* (headerLine NEWLINE*)* (dataList | routine (NEWLINE* routine)*) NEWLINE* EOF
    ;

// &ACCESS, &REL, &PARAM, &COMMENT lines at the top of a file (reference 1.3).
headerLine
    : HEADER NEWLINE
    ;

// ------------------------------------------------------------------ routines (2.2-2.4)

routine
    : procedureDefinition
    | functionDefinition
    ;

procedureDefinition
    : GLOBAL? DEF name '(' parameterList? ')' NEWLINE routineBody END NEWLINE
    ;

functionDefinition
    : GLOBAL? DEFFCT typeRef name '(' parameterList? ')' NEWLINE routineBody ENDFCT NEWLINE
    ;

parameterList
    : parameter (',' parameter)*
    ;

// An array parameter carries empty brackets, one comma per extra dimension: A[], M[,] (2.3).
parameter
    : name openDimensions? (':' (IN | OUT))?
    ;

openDimensions
    : '[' (',' ','?)? ']'
    ;

// Declarations precede statements (2.2): a DECL after the first statement is a syntax error.
// Blank and comment lines before and between declarations belong to routineBody itself, and
// those after the last one to the statement list: every blank line has one owner, so the
// parser decides declaration-or-statement once per run of blank lines, not once per line
// (a run of n blank lines used to cost n lookaheads of n tokens each, quadratic).
routineBody
    : (NEWLINE* declarationLine)* statementList
    ;

declarationLine
    : declaration NEWLINE
    ;

statementList
    : statementLine*
    ;

statementLine
    : (statement | label)? NEWLINE
    ;

label
    : name ':'
    ;

// ------------------------------------------------------------------ data lists (2.5)

dataList
    : DEFDAT name PUBLIC? NEWLINE dataItemLine* ENDDAT NEWLINE
    ;

dataItemLine
    : dataItem? NEWLINE
    ;

dataItem
    : dataVariableDeclaration
    | arrayElementInitialisation
    | stringInitialisation
    | structureDeclaration
    | enumDeclaration
    | signalDeclaration
    | externalDeclaration
    | importDeclaration
    | channelDeclaration
    ;

// DECL is optional before the simple types and the predefined geometric structure types (2.5);
// user-defined types need it.
// A CONST must be initialised on the same line (2.5), except a CONST array, whose elements
// are initialised on the following lines (ARR[1]=...).
// Several names on one line only without initial values (3.2).
dataVariableDeclaration
    : DECL GLOBAL? typeName variableName ('=' constantValue | (',' variableName)*)
    | DECL GLOBAL? CONST typeName (variableName '=' constantValue | constantArrayName)
    | GLOBAL? simpleType variableName ('=' constantValue | (',' variableName)*)
    | GLOBAL? CONST simpleType (variableName '=' constantValue | constantArrayName)
    | GLOBAL? geometricType variableName ('=' constantValue | (',' variableName)*)
    | GLOBAL? CONST geometricType (variableName '=' constantValue | constantArrayName)
    ;

constantArrayName
    : name arrayDimensions
    ;

// Arrays have 1 to 3 dimensions (3.3); an empty last index selects a CHAR-array row: N[3,]="x".
arrayElementInitialisation
    : name '[' constantIndex (',' (constantIndex (',' constantIndex?)?)?)? ']' '=' constantValue
    ;

constantIndex
    : INTLITERAL
    ;

// A whole CHAR array (string) initialised after its declaration: NAME[]="text" (2.5, 3.4).
stringInitialisation
    : name '[' ']' '=' STRINGLITERAL
    ;

// Only literals (with a leading sign) and literal aggregates initialise data-list variables (1.5).
constantValue
    : sign=('-' | '+')? (INTLITERAL | REALLITERAL)
    | HEXLITERAL
    | BINLITERAL
    | TRUE
    | FALSE
    | STRINGLITERAL
    | ENUMLITERAL
    | constantAggregate
    ;

constantAggregate
    : '{' (typeName ':')? constantComponent (',' constantComponent)* '}'
    ;

constantComponent
    : (name | contextKeyword) ('[' ']')? constantValue
    ;

channelDeclaration
    : CHANNEL ':' name ':' name name
    ;

importDeclaration
    : IMPORT typeName name IS '/' name '/' name '..' name
    ;

// ------------------------------------------------------------------ declarations (3)

declaration
    : variableDeclaration
    | constantDeclaration
    | structureDeclaration
    | enumDeclaration
    | signalDeclaration
    | externalDeclaration
    | importDeclaration
    ;

// A local constant: DECL CONST with its literal value on the same line. The reference keeps
// CONST to data lists (2.5); the project's requirements (issue 3) ask for constants in a
// routine's declaration section too, which is how KSS 8 code declares local limits.
// Only scalars: a constant array would need element assignments, which are statements.
constantDeclaration
    : DECL CONST typeName variableName '=' constantValue
    | CONST (simpleType | geometricType) variableName '=' constantValue
    ;

// In a routine: no initial values (2.2).
// Array parameters are declared with open dimensions, DECL CHAR buf[] (2.3): routines only.
variableDeclaration
    : DECL typeName (variableName | openArrayName) (',' (variableName | openArrayName))*
    | simpleType (variableName | openArrayName) (',' (variableName | openArrayName))*
    | geometricType (variableName | openArrayName) (',' (variableName | openArrayName))*
    ;

openArrayName
    : name openDimensions
    ;

variableName
    : name arrayDimensions?
    ;

arrayDimensions
    : '[' INTLITERAL (',' INTLITERAL (',' INTLITERAL)?)? ']'
    ;

structureDeclaration
    : GLOBAL? STRUC name typeName structureComponent (',' typeName? structureComponent)*
    ;

structureComponent
    : (name | contextKeyword) arrayDimensions?
    ;

enumDeclaration
    : GLOBAL? ENUM name (name | contextKeyword) (',' (name | contextKeyword))*
    ;

// A system signal that is not wired is declared FALSE in KUKA's machine data
// ($machine.dat: SIGNAL $MODE_TEST FALSE).
signalDeclaration
    : GLOBAL? SIGNAL name signalReference (TO signalReference)?
    | SIGNAL SYSNAME FALSE
    ;

signalReference
    : SYSNAME '[' INTLITERAL ']'
    ;

// EXT/EXTP procedure and EXTFCT/EXTFCTP function signatures (2.6).
externalDeclaration
    : (EXT | EXTP) name '(' externalParameterList? ')'
    | (EXTFCT | EXTFCTP) typeRef name '(' externalParameterList? ')'
    ;

externalParameterList
    : externalParameter (',' externalParameter)*
    ;

externalParameter
    : typeName ('[' INTLITERAL? ']')? (name ('[' INTLITERAL? ']')?)? (':' (IN | OUT))?
    ;

typeRef
    : typeName ('[' INTLITERAL? ']')?
    ;

typeName
    : simpleType
    | geometricType
    | IDENTIFIER
    ;

simpleType
    : INT
    | REAL
    | BOOL
    | CHAR
    ;

// The predefined geometric structures (3.7), the only structure types written without DECL
// in real code (`FRAME f`, `E6POS XP1={...}`, `E6AXIS XHOME={...}`; 2.5).
geometricType
    : AXIS
    | E3AXIS
    | E6AXIS
    | FRAME
    | POS
    | E3POS
    | E6POS
    ;

// ------------------------------------------------------------------ statements (5)

statement
    : assignment                                                    # assignmentStatement
    | call                                                          # callStatement
    | IF expression THEN NEWLINE statementList
      (ELSE NEWLINE statementList)? ENDIF                           # ifStatement
    | SWITCH expression NEWLINE+ switchCase+ switchDefault? ENDSWITCH # switchStatement
    | FOR name '=' expression TO expression (STEP expression)?
      NEWLINE statementList ENDFOR                                  # forStatement
    | WHILE expression NEWLINE statementList ENDWHILE               # whileStatement
    | REPEAT NEWLINE statementList UNTIL expression                 # repeatStatement
    | LOOP NEWLINE statementList ENDLOOP                            # loopStatement
    | EXIT                                                          # exitStatement
    | GOTO name                                                     # gotoStatement
    | HALT                                                          # haltStatement
    | WAIT FOR expression                                           # waitForStatement
    | WAIT SEC expression                                           # waitSecStatement
    | CONTINUE                                                      # continueStatement
    | RETURN expression?                                            # returnStatement
    | ON_ERROR_PROCEED                                              # onErrorProceedStatement
    | CONFIRM expression                                            # confirmStatement
    | GLOBAL? INTERRUPT DECL priority WHEN expression DO
      (call | BRAKE | BRAKE_F)                                      # interruptDeclaration
    | INTERRUPT action=(ON | OFF | ENABLE | DISABLE) priority?      # interruptControl
    | BRAKE                                                         # brakeStatement
    | BRAKE_F                                                       # brakeFStatement
    | RESUME                                                        # resumeStatement
    | triggerStatement                                              # triggerStatementAlt
    | conditionalStop                                               # conditionalStopStatement
    | ANIN ON variable '=' expression                               # aninOnStatement
    | ANIN OFF name                                                 # aninOffStatement
    | ANOUT ON name '=' expression (DELAY '=' expression)?
      (MINIMUM '=' expression)? (MAXIMUM '=' expression)?           # anoutOnStatement
    | ANOUT OFF name                                                # anoutOffStatement
    | motion                                                        # motionStatement
    | splineBlock                                                   # splineBlockStatement
    | ASYPTP expression                                             # asyptpStatement
    | MOVE_EMI variable STRINGLITERAL (name expression)?            # moveEmiStatement
    ;

assignment
    : variable '=' expression
    ;

call
    : name '(' argumentList? ')'
    ;

// Omitted arguments leave an empty slot: F(a, , c) (2.3).
argumentList
    : argument (',' argument?)*
    | (',' argument?)+
    ;

argument
    : expression
    | channelName
    ;

// A channel of the controller as a call argument, COPEN(:SER_3, HANDLE) (KUKA's serial
// channels of the CREAD/CWRITE interface; declared by CHANNEL lines of $custom.dat).
channelName
    : ':' name
    ;

switchCase
    : CASE expression (',' expression)* NEWLINE statementList
    ;

switchDefault
    : DEFAULT NEWLINE statementList
    ;

priority
    : INTLITERAL
    | name
    ;

// Path-synchronous actions (5.18): DISTANCE is the start (0) or end (1) point of the motion.
triggerStatement
    : TRIGGER WHEN DISTANCE '=' point=INTLITERAL  // 0 or 1: checked after the parse (krl/syntax/checks.py)
      DELAY '=' expression DO triggerAction
      (PRIO '=' expression)?
    | TRIGGER WHEN PATH '=' expression ONSTART? DELAY '=' expression DO triggerAction
      (PRIO '=' expression)?
    ;

triggerAction
    : assignment
    | call
    ;

// Conditional stop (KSS 8.3 and later; grammar/CHANGES.md, issue 63): the robot stops on the
// path of the next motion (segment) PATH mm from its end point (its start point with ONSTART)
// when the condition holds there. STOP is no reserved word (a name anywhere else): the word
// under the label word= is checked after the parse (krl/syntax/checks.py).
conditionalStop
    : word=IDENTIFIER WHEN PATH '=' expression ONSTART? IF expression
    ;

// ------------------------------------------------------------------ motions (6.1)

// A relative motion may name its reference frame, #BASE (default) or #TOOL (6.1, 6.3); the
// grammar takes any enum literal under the label frame=, checked after the parse
// (krl/syntax/checks.py), so that every ANTLR target runs this grammar.
motion
    : PTP expression approximation? approximation?                                   # ptpMotion
    | PTP_REL expression approximation? approximation?
      (frame=ENUMLITERAL)? # ptpRelMotion
    | LIN expression approximation? approximation?                                   # linMotion
    | LIN_REL expression approximation? approximation?
      (frame=ENUMLITERAL)? # linRelMotion
    | CIRC expression ',' expression (',' CA expression)? approximation? approximation? # circMotion
    | CIRC_REL expression ',' expression (',' CA expression)? approximation?
      (frame=ENUMLITERAL)? # circRelMotion
    | SPTP expression withClause? splineApproximation?                               # sptpMotion
    | SLIN expression withClause? splineApproximation?                               # slinMotion
    | SCIRC expression ',' expression (',' CA expression)? withClause? C_SPL?        # scircMotion
    | SPTP_REL expression withClause? splineApproximation?
      (frame=ENUMLITERAL)? # sptpRelMotion
    | SLIN_REL expression withClause? splineApproximation?
      (frame=ENUMLITERAL)? # slinRelMotion
    | SCIRC_REL expression ',' expression (',' CA expression)? withClause? C_SPL?
      (frame=ENUMLITERAL)? # scircRelMotion
    ;

// Spline blocks (6.2): one motion through all segments; inside only segments, TRIGGERs,
// blank and comment lines.
splineBlock
    : SPLINE withClause? NEWLINE splineBlockLine* ENDSPLINE C_SPL?          # cartesianSplineBlock
    | PTP_SPLINE withClause? NEWLINE ptpSplineBlockLine* ENDSPLINE C_SPL?   # ptpSplineBlock
    ;

splineBlockLine
    : (splineSegment | triggerStatement | conditionalStop)? NEWLINE
    ;

splineSegment
    : SPL expression withClause?                                            # splSegment
    | SLIN expression withClause?                                           # slinSegment
    | SCIRC expression ',' expression (',' CA expression)? withClause?      # scircSegment
    ;

ptpSplineBlockLine
    : (ptpSplineSegment | triggerStatement | conditionalStop)? NEWLINE
    ;

ptpSplineSegment
    : SPTP expression withClause?
    ;

approximation
    : C_PTP
    | C_DIS
    | C_VEL
    | C_ORI
    ;

splineApproximation
    : C_SPL
    | C_DIS
    | C_PTP
    ;

withClause
    : WITH withAssignment (',' withAssignment)*
    ;

withAssignment
    : systemVariable '=' expression
    ;

systemVariable
    : SYSNAME selector*
    ;

// ------------------------------------------------------------------ expressions (4)

// Alternatives are listed from the highest to the lowest priority (reference 4.1);
// comparisons bind weaker than AND/OR.
expression
    : primary                                                     # primaryExpression
    | op=('-' | '+' | NOT | B_NOT) expression                     # unaryExpression
    | expression ':' expression                                   # geometricExpression
    | expression op=('*' | '/') expression                        # multiplicativeExpression
    | expression op=('+' | '-') expression                        # additiveExpression
    | expression op=(AND | B_AND) expression                      # andExpression
    | expression op=(EXOR | B_EXOR) expression                    # exorExpression
    | expression op=(OR | B_OR) expression                        # orExpression
    | expression op=('==' | '<>' | '<' | '>' | '<=' | '>=') expression # relationalExpression
    ;

primary
    : literal                                                     # literalPrimary
    | aggregate                                                   # aggregatePrimary
    | call                                                        # callPrimary
    | variable                                                    # variablePrimary
    | '(' expression ')'                                          # parenthesisedPrimary
    ;

variable
    : name selector*
    ;

// a[i], m[i,j], names[2,] (row of a CHAR array), s[] (whole CHAR array), p.X
selector
    : '[' expression? (',' expression?)* ']'
    | '.' (name | contextKeyword)
    ;

aggregate
    : '{' (typeName ':')? aggregateComponent (',' aggregateComponent)* '}'
    ;

aggregateComponent
    : (name | contextKeyword) ('[' ']')? expression
    ;

literal
    : INTLITERAL
    | REALLITERAL
    | HEXLITERAL
    | BINLITERAL
    | TRUE
    | FALSE
    | STRINGLITERAL
    | ENUMLITERAL
    ;

// The predefined geometric type names are tokens (for DECL-less declarations, 2.5) but not
// keywords: "ordinary type identifiers" (1.6), so they are names wherever a name may stand.
// The attribute words of interrupt, trigger and analog-output statements are names too
// (grammar/CHANGES.md, "attribute keywords as names"): each stands only right after its own
// statement's keyword or as `WORD=` inside it, never at a statement's start or between an
// expression and an operator, so a name spelled alike is never ambiguous, and real backups
// name parameters and variables so (`DEF SetGripper(ENABLE :IN)`).
// STEP is a name too (grammar/CHANGES.md, "STEP as a name"): the keyword stands only after
// FOR's `TO expression`, where no name can follow an expression, and published programs
// name variables and parameters `step` (`DECL INT step`, `RSI_SETPUBLICPAR(.., step)`).
name
    : IDENTIFIER
    | STEP
    | SYSNAME
    | AXIS
    | E3AXIS
    | E6AXIS
    | FRAME
    | POS
    | E3POS
    | E6POS
    | attributeKeyword
    ;

attributeKeyword
    : ENABLE
    | DISABLE
    | ONSTART
    | DELAY
    | PRIO
    | MINIMUM
    | MAXIMUM
    ;

// Keywords that KUKA's own data lists use as structure components and enum values
// (`STRUC DATE INT CSEC,SEC,...`, `ENUM SW_ONOFF ON,OFF`, `P[1].OUT`; IN/OUT are keywords
// only after ':', 1.6). Accepted only in component and enum-value positions. (STEP, once
// here, is a `name`.)
contextKeyword
    : IN
    | OUT
    | ON
    | OFF
    | PATH
    | SEC
    | DISTANCE
    ;

// ======================================================================== lexer

// Header lines (1.3): the four documented kinds and &USER (owner tag of technology packages).
HEADER : '&' ('ACCESS' | 'REL' | 'PARAM' | 'COMMENT' | 'USER') ~[\r\n]* ;

// Folds and comments (1.3): structural comments on the hidden channel.
FOLD    : ';' [ \t]* 'FOLD' ~[\r\n]*    -> channel(HIDDEN) ;
ENDFOLD : ';' [ \t]* 'ENDFOLD' ~[\r\n]* -> channel(HIDDEN) ;
COMMENT : ';' ~[\r\n]*                  -> channel(HIDDEN) ;

NEWLINE : '\r'? '\n' | '\r' ;
WS      : [ \t\f]+ -> skip ;

// Keywords (1.6).
AND : 'AND' ;
ANIN : 'ANIN' ;
ANOUT : 'ANOUT' ;
ASYCANCEL : 'ASYCANCEL' ;
ASYCONT : 'ASYCONT' ;
ASYPTP : 'ASYPTP' ;
ASYSTOP : 'ASYSTOP' ;
B_AND : 'B_AND' ;
B_EXOR : 'B_EXOR' ;
B_NOT : 'B_NOT' ;
B_OR : 'B_OR' ;
BOOL : 'BOOL' ;
BRAKE_F : 'BRAKE' [ \t]+ 'F' ;
BRAKE : 'BRAKE' ;
C_DIS : 'C_DIS' ;
C_ORI : 'C_ORI' ;
C_PTP : 'C_PTP' ;
C_SPL : 'C_SPL' ;
C_VEL : 'C_VEL' ;
CA : 'CA' ;
CASE : 'CASE' ;
CHANNEL : 'CHANNEL' ;
CHAR : 'CHAR' ;
CIRC : 'CIRC' ;
CIRC_REL : 'CIRC_REL' ;
CONFIRM : 'CONFIRM' ;
CONST : 'CONST' ;
CONST_VEL : 'CONST_VEL' ;
CONTINUE : 'CONTINUE' ;
DECL : 'DECL' ;
DEF : 'DEF' ;
DEFAULT : 'DEFAULT' ;
DEFDAT : 'DEFDAT' ;
DEFFCT : 'DEFFCT' ;
DELAY : 'DELAY' ;
DIGIN : 'DIGIN' ;
DISABLE : 'DISABLE' ;
DISTANCE : 'DISTANCE' ;
DO : 'DO' ;
ELSE : 'ELSE' ;
ENABLE : 'ENABLE' ;
END : 'END' ;
ENDDAT : 'ENDDAT' ;
ENDFCT : 'ENDFCT' ;
ENDFOR : 'ENDFOR' ;
ENDIF : 'ENDIF' ;
ENDLOOP : 'ENDLOOP' ;
ENDSPLINE : 'ENDSPLINE' ;
ENDSWITCH : 'ENDSWITCH' ;
ENDWHILE : 'ENDWHILE' ;
ENUM : 'ENUM' ;
EXIT : 'EXIT' ;
EXOR : 'EXOR' ;
EXT : 'EXT' ;
EXTFCT : 'EXTFCT' ;
EXTFCTP : 'EXTFCTP' ;
EXTP : 'EXTP' ;
FALSE : 'FALSE' ;
FOR : 'FOR' ;
GLOBAL : 'GLOBAL' ;
GOTO : 'GOTO' ;
HALT : 'HALT' ;
IF : 'IF' ;
IMPORT : 'IMPORT' ;
IN : 'IN' ;
INT : 'INT' ;
INTERRUPT : 'INTERRUPT' ;
IS : 'IS' ;
LIN : 'LIN' ;
LIN_REL : 'LIN_REL' ;
LOOP : 'LOOP' ;
MAXIMUM : 'MAXIMUM' ;
MINIMUM : 'MINIMUM' ;
MOVE_EMI : 'MOVE_EMI' ;
NOT : 'NOT' ;
OFF : 'OFF' ;
ON : 'ON' ;
ON_ERROR_PROCEED : 'ON_ERROR_PROCEED' ;
ONSTART : 'ONSTART' ;
OR : 'OR' ;
OUT : 'OUT' ;
PATH : 'PATH' ;
PRIO : 'PRIO' ;
PTP : 'PTP' ;
PTP_REL : 'PTP_REL' ;
PTP_SPLINE : 'PTP_SPLINE' ;
PUBLIC : 'PUBLIC' ;
REAL : 'REAL' ;
REPEAT : 'REPEAT' ;
RESUME : 'RESUME' ;
RETURN : 'RETURN' ;
SCIRC : 'SCIRC' ;
SCIRC_REL : 'SCIRC_REL' ;
SEC : 'SEC' ;
SIGNAL : 'SIGNAL' ;
SLIN : 'SLIN' ;
SLIN_REL : 'SLIN_REL' ;
SPL : 'SPL' ;
SPLINE : 'SPLINE' ;
SPTP : 'SPTP' ;
SPTP_REL : 'SPTP_REL' ;
STEP : 'STEP' ;
STRUC : 'STRUC' ;
SWITCH : 'SWITCH' ;
THEN : 'THEN' ;
TIME_BLOCK : 'TIME_BLOCK' ;
TO : 'TO' ;
TRIGGER : 'TRIGGER' ;
TRUE : 'TRUE' ;
UNTIL : 'UNTIL' ;
WAIT : 'WAIT' ;
WHEN : 'WHEN' ;
WHILE : 'WHILE' ;
WITH : 'WITH' ;

// Predefined geometric structure types (3.7): type names, not usable as variable names.
AXIS : 'AXIS' ;
E3AXIS : 'E3AXIS' ;
E6AXIS : 'E6AXIS' ;
FRAME : 'FRAME' ;
POS : 'POS' ;
E3POS : 'E3POS' ;
E6POS : 'E6POS' ;

// Literals (1.5).
HEXLITERAL    : '\'' 'H' [0-9A-F]+ '\'' ;
BINLITERAL    : '\'' 'B' [01]+ '\'' ;
REALLITERAL   : [0-9]+ '.' [0-9]* EXPONENT? | '.' [0-9]+ EXPONENT? | [0-9]+ EXPONENT ;
INTLITERAL    : [0-9]+ ;
STRINGLITERAL : '"' ~["\r\n]* '"' ;
ENUMLITERAL   : '#' [A-Z_] [A-Z0-9_]* ;
fragment EXPONENT : 'E' [+-]? [0-9]+ ;

// Names (1.2): system names start with '$'.
SYSNAME    : '$' [A-Z0-9_$]* ;
IDENTIFIER : [A-Z_] [A-Z0-9_$]* ;

// Operators and punctuation.
EQ     : '==' ;
NE     : '<>' ;
LE     : '<=' ;
GE     : '>=' ;
LT     : '<' ;
GT     : '>' ;
ASSIGN : '=' ;
PLUS   : '+' ;
MINUS  : '-' ;
STAR   : '*' ;
SLASH  : '/' ;
COLON  : ':' ;
COMMA  : ',' ;
DOTDOT : '..' ;
DOT    : '.' ;
LPAREN : '(' ;
RPAREN : ')' ;
LBRACK : '[' ;
RBRACK : ']' ;
LBRACE : '{' ;
RBRACE : '}' ;
