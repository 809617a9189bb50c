// The Java parse engine's worker (krl/syntax/engines/java.py starts it; docs/architecture.md,
// "Parse engines"). It runs the KRLLexer/KRLParser that the ANTLR 4.13.2 tool generated from
// one version of grammar/KRL.g4 (loaded by name from the class path) and does exactly what
// krl/syntax/parse.py does with the Python runtime, and nothing more:
//
//   stage 1: SLL prediction with BailErrorStrategy; a file with no lexer error that parses
//            here is ok;
//   stage 2: full LL with LineErrorStrategy (the port of krl/syntax/errors.py), collecting
//            every error's raw data.
//
// Everything else (display names, the line shape, cascade marks, messages in KRL words, the
// limit pre-pass and the post-parse checks) stays in Python and is applied to these raw
// records, so it exists once. The two ports (LineErrorStrategy, lineTokens) are tested
// against the Python originals on every file of the corpora (tests/syntax/test_engines.py).
//
// Protocol: requests on stdin, "<id> <n>\n" (or "<id> <n> t\n": with the parse tree; a further
// "L<line>": the text is a piece of a file whose first line is that line number) followed
// by n bytes of UTF-8 KRL text (already decoded and given its final newline by Python); one
// JSON line per request on stdout, {"id": .., "stage": "sll"|"ll", "lex": [[line, column, msg],
// ..], "syn": [{..}, ..]} or {"id": .., "fail": "<exception>"}. Requests are parsed on a thread
// pool; answers come in completion order. "0 -1\n" (or end of input) stops the worker.
//
// With "t" the answer also carries the parse tree that the stage's parser built, as data
// (krl/syntax/engines/tree.py rebuilds the Python runtime's objects from it; nothing is
// re-parsed):
//   "tokens": every token of the stream, 6 integers each: type, channel, start and stop (code
//             point offsets in the text), line, column; a token's index is its tokenIndex;
//   "names":  the context class names the tree uses (the generated Java and Python parsers
//             name them alike, e.g. "UnaryExpressionContext");
//   "tree":   the nodes in preorder, integers: a rule context is
//             name index, start token, stop token (-1: none), invoking state, 1 when the rule
//             recorded a recognition exception else 0, number of children, then its children;
//             a terminal is -1, token index; an error node -2, token index;
//   "labels": [[context's preorder number among contexts, field, kind, value], ..] for every
//             label field (`op=`, `frame=` ..) of the contexts: kind "t" a token index (-1:
//             null), "c" the index of a child (-1: null), "T"/"C" lists of those.

import java.io.BufferedOutputStream;
import java.io.DataInputStream;
import java.io.IOException;
import java.io.InputStream;
import java.io.OutputStream;
import java.io.PrintStream;
import java.lang.reflect.Constructor;
import java.lang.reflect.Method;
import java.nio.charset.StandardCharsets;
import java.lang.reflect.Field;
import java.lang.reflect.Modifier;
import java.util.ArrayDeque;
import java.util.ArrayList;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import java.util.concurrent.ConcurrentHashMap;
import java.util.concurrent.ExecutorService;
import java.util.concurrent.Executors;
import java.util.concurrent.ThreadFactory;
import java.util.concurrent.TimeUnit;

import org.antlr.v4.runtime.BailErrorStrategy;
import org.antlr.v4.runtime.BaseErrorListener;
import org.antlr.v4.runtime.CharStream;
import org.antlr.v4.runtime.CharStreams;
import org.antlr.v4.runtime.CommonTokenStream;
import org.antlr.v4.runtime.DefaultErrorStrategy;
import org.antlr.v4.runtime.InputMismatchException;
import org.antlr.v4.runtime.Lexer;
import org.antlr.v4.runtime.LexerNoViableAltException;
import org.antlr.v4.runtime.Parser;
import org.antlr.v4.runtime.ParserRuleContext;
import org.antlr.v4.runtime.RecognitionException;
import org.antlr.v4.runtime.Recognizer;
import org.antlr.v4.runtime.Token;
import org.antlr.v4.runtime.TokenStream;
import org.antlr.v4.runtime.atn.ATNState;
import org.antlr.v4.runtime.atn.PredictionMode;
import org.antlr.v4.runtime.misc.IntervalSet;
import org.antlr.v4.runtime.misc.ParseCancellationException;
import org.antlr.v4.runtime.tree.ErrorNode;
import org.antlr.v4.runtime.tree.ParseTree;
import org.antlr.v4.runtime.tree.TerminalNode;

public final class KrlWorker {

    static Constructor<?> lexerNew;
    static Constructor<?> parserNew;
    static Method startRule;
    static int newlineType;
    static String parserClassName;

    /** krl/syntax/errors.py LineErrorStrategy: report, then resynchronise at the end of the line. */
    static final class LineErrorStrategy extends DefaultErrorStrategy {
        @Override
        public Token recoverInline(Parser recognizer) {
            // No single-token insertion or deletion: they hide errors and bend the tree.
            throw new InputMismatchException(recognizer);
        }

        @Override
        public void recover(Parser recognizer, RecognitionException e) {
            TokenStream stream = recognizer.getInputStream();
            if (lastErrorIndex == stream.index() && lastErrorStates != null
                    && lastErrorStates.contains(recognizer.getState()) && stream.LA(1) != Token.EOF) {
                recognizer.consume();  // no progress since the last error here: force it
            }
            lastErrorIndex = stream.index();
            if (lastErrorStates == null) {
                lastErrorStates = new IntervalSet();
            }
            lastErrorStates.add(recognizer.getState());
            skipLine(recognizer);
        }

        @Override
        public void sync(Parser recognizer) {
            if (inErrorRecoveryMode(recognizer)) {
                return;
            }
            ATNState state = recognizer.getInterpreter().atn.states.get(recognizer.getState());
            switch (state.getStateType()) {
                case ATNState.BLOCK_START: case ATNState.STAR_BLOCK_START: case ATNState.PLUS_BLOCK_START:
                case ATNState.STAR_LOOP_ENTRY: case ATNState.STAR_LOOP_BACK: case ATNState.PLUS_LOOP_BACK:
                    break;
                default:
                    return;
            }
            TokenStream stream = recognizer.getInputStream();
            int la = stream.LA(1);
            if (la == Token.EOF) {
                return;
            }
            IntervalSet next = recognizer.getATN().nextTokens(state);
            if (next.contains(la)) {
                return;
            }
            if (next.contains(Token.EPSILON) && recognizer.getExpectedTokens().contains(la)) {
                return;
            }
            // A token that can neither continue nor end this list: report it, skip the line.
            beginErrorCondition(recognizer);
            Token token = recognizer.getCurrentToken();
            IntervalSet expecting = getExpectedTokens(recognizer);
            String msg = "extraneous input " + getTokenErrorDisplay(token) + " expecting "
                    + expecting.toString(recognizer.getVocabulary());
            recognizer.notifyErrorListeners(token, msg, null);
            skipLine(recognizer);
            endErrorCondition(recognizer);
        }

        private void skipLine(Parser recognizer) {
            TokenStream stream = recognizer.getInputStream();
            while (stream.LA(1) != Token.EOF && stream.LA(1) != newlineType) {
                recognizer.consume();
            }
        }
    }

    /** Raw lexer errors: line, column, message (Python's finish_lexer does the rest). */
    static final class LexerErrors extends BaseErrorListener {
        final StringBuilder out = new StringBuilder();
        int count;

        @Override
        public void syntaxError(Recognizer<?, ?> r, Object sym, int line, int col, String msg, RecognitionException e) {
            out.append(count++ == 0 ? "" : ",").append('[').append(line).append(',').append(col).append(',');
            str(out, msg);
            out.append(']');
            keepLineEnd((Lexer) r, e);
        }

        /** krl/syntax/errors.py line_end_lexer: the line end a token recognition error stopped at
         *  stays a token (the lexer's skip takes the last character read instead). */
        static void keepLineEnd(Lexer lexer, RecognitionException e) {
            CharStream in = lexer.getInputStream();
            if (!(e instanceof LexerNoViableAltException) || in == null
                    || in.index() <= ((LexerNoViableAltException) e).getStartIndex()
                    || (in.LA(1) != '\n' && in.LA(1) != '\r')) {
                return;
            }
            lexer.setCharPositionInLine(lexer.getCharPositionInLine() - 1);   // the skip counts it again
            in.seek(in.index() - 1);
        }
    }

    /** Raw syntax errors: what CollectingErrorListener.syntaxError reads from the recognizer. */
    static final class SyntaxErrors extends BaseErrorListener {
        final StringBuilder out = new StringBuilder();
        final CommonTokenStream tokens;
        int count;

        SyntaxErrors(CommonTokenStream tokens) {
            this.tokens = tokens;
        }

        @Override
        public void syntaxError(Recognizer<?, ?> r, Object sym, int line, int col, String msg, RecognitionException e) {
            Parser parser = (Parser) r;
            Token tok = (Token) sym;
            StringBuilder b = out;
            b.append(count++ == 0 ? "{" : ",{").append("\"line\":").append(line).append(",\"column\":").append(col);
            b.append(",\"msg\":");
            str(b, msg);
            b.append(",\"type\":").append(tok != null ? tok.getType() : Token.EOF).append(",\"text\":");
            str(b, tok != null ? tok.getText() : "<EOF>");
            b.append(",\"expected\":");
            try {
                IntervalSet expected = parser.getExpectedTokens();
                b.append('[');
                List<Integer> list = expected.toList();
                for (int i = 0; i < list.size(); i++) {
                    b.append(i == 0 ? "" : ",").append(list.get(i));
                }
                b.append(']');
            } catch (RuntimeException ex) {  // an odd ATN state must not abort a scan
                b.append("[]");
            }
            b.append(",\"stack\":[");
            List<String> stack = parser.getRuleInvocationStack();
            for (int i = 0; i < stack.size(); i++) {
                if (i > 0) {
                    b.append(',');
                }
                str(b, stack.get(i));
            }
            b.append("],\"line_tokens\":[");
            List<Token> lineToks = lineTokens(tok);
            for (int i = 0; i < lineToks.size(); i++) {
                Token t = lineToks.get(i);
                b.append(i == 0 ? "[" : ",[").append(t.getType()).append(',');
                str(b, t.getText());
                b.append(']');
            }
            b.append("]}");
        }

        /** krl/syntax/errors.py _line_tokens: default-channel tokens of the token's line, up to it. */
        List<Token> lineTokens(Token token) {
            List<Token> result = new ArrayList<>();
            if (token == null) {
                return result;
            }
            int i = token.getTokenIndex();
            if (i < 0) {
                result.add(token);
                return result;
            }
            List<Token> toks = tokens.getTokens();
            int start = i;
            while (start > 0) {
                Token prev = toks.get(start - 1);
                if (prev.getType() == newlineType || prev.getType() == Token.EOF) {
                    break;
                }
                start--;
            }
            for (int k = start; k <= i; k++) {
                Token t = toks.get(k);
                if (t.getChannel() == Token.DEFAULT_CHANNEL) {
                    result.add(t);
                }
            }
            return result;
        }
    }

    static void str(StringBuilder b, String s) {
        if (s == null) {
            b.append("null");
            return;
        }
        b.append('"');
        for (int i = 0; i < s.length(); i++) {
            char c = s.charAt(i);
            switch (c) {
                case '"': b.append("\\\""); break;
                case '\\': b.append("\\\\"); break;
                case '\n': b.append("\\n"); break;
                case '\r': b.append("\\r"); break;
                case '\t': b.append("\\t"); break;
                default:
                    if (c < 0x20 || (c >= 0xD800 && c <= 0xDFFF && !validSurrogate(s, i))) {
                        b.append(String.format("\\u%04x", (int) c));
                    } else {
                        b.append(c);
                    }
            }
        }
        b.append('"');
    }

    static boolean validSurrogate(String s, int i) {
        char c = s.charAt(i);
        if (Character.isHighSurrogate(c)) {
            return i + 1 < s.length() && Character.isLowSurrogate(s.charAt(i + 1));
        }
        return i > 0 && Character.isHighSurrogate(s.charAt(i - 1));
    }

    static String parse(long id, String text, boolean wantTree, int firstLine) throws Exception {
        Lexer lexer = (Lexer) lexerNew.newInstance(CharStreams.fromString(text));
        if (firstLine != 1) {
            lexer.setLine(firstLine);   // a piece of a file: tokens carry the file's line numbers
        }
        lexer.removeErrorListeners();
        LexerErrors lexErrors = new LexerErrors();
        lexer.addErrorListener(lexErrors);
        CommonTokenStream tokens = new CommonTokenStream(lexer);
        tokens.fill();

        // Stage 1: SLL with bail-out.
        Parser parser = (Parser) parserNew.newInstance(tokens);
        parser.removeErrorListeners();
        parser.getInterpreter().setPredictionMode(PredictionMode.SLL);
        parser.setErrorHandler(new BailErrorStrategy());
        ParserRuleContext tree = null;
        boolean sllOk;
        try {
            tree = (ParserRuleContext) startRule.invoke(parser);
            sllOk = true;
        } catch (java.lang.reflect.InvocationTargetException ex) {
            if (!(ex.getCause() instanceof ParseCancellationException)) {
                throw ex;
            }
            sllOk = false;
        }
        if (sllOk && lexErrors.count == 0) {
            StringBuilder b = new StringBuilder("{\"id\":").append(id).append(",\"stage\":\"sll\",\"lex\":[],\"syn\":[]");
            if (wantTree) {
                treeData(b, tokens, tree);
            }
            return b.append('}').toString();
        }

        // Stage 2: full LL with line-oriented recovery, collecting every error.
        tokens.seek(0);
        parser = (Parser) parserNew.newInstance(tokens);
        parser.removeErrorListeners();
        SyntaxErrors synErrors = new SyntaxErrors(tokens);
        parser.addErrorListener(synErrors);
        parser.getInterpreter().setPredictionMode(PredictionMode.LL);
        parser.setErrorHandler(new LineErrorStrategy());
        tree = (ParserRuleContext) startRule.invoke(parser);
        StringBuilder b = new StringBuilder("{\"id\":").append(id).append(",\"stage\":\"ll\",\"lex\":[")
                .append(lexErrors.out).append("],\"syn\":[").append(synErrors.out).append(']');
        if (wantTree) {
            treeData(b, tokens, tree);
        }
        return b.append('}').toString();
    }

    /** The label fields (`op=`, `frame=`, `x+=`) the generated code declares on a context class. */
    static final Map<Class<?>, Field[]> LABELS = new ConcurrentHashMap<>();

    static Field[] labelFields(Class<?> cls) {
        return LABELS.computeIfAbsent(cls, c -> {
            List<Field> out = new ArrayList<>();
            for (Field f : c.getFields()) {
                if (Modifier.isStatic(f.getModifiers())
                        || !f.getDeclaringClass().getName().startsWith(parserClassName + "$")) {
                    continue;
                }
                out.add(f);
            }
            out.sort((a, b) -> a.getName().compareTo(b.getName()));
            return out.toArray(new Field[0]);
        });
    }

    /** ",\"tokens\":[..],\"names\":[..],\"tree\":[..],\"labels\":[..]" (see the header). */
    static void treeData(StringBuilder b, CommonTokenStream tokens, ParserRuleContext root) throws IllegalAccessException {
        b.append(",\"tokens\":[");
        List<Token> all = tokens.getTokens();
        for (int i = 0; i < all.size(); i++) {
            Token t = all.get(i);
            if (t.getTokenIndex() != i) {
                throw new IllegalStateException("token index " + t.getTokenIndex() + " at " + i);
            }
            b.append(i == 0 ? "" : ",").append(t.getType()).append(',').append(t.getChannel()).append(',')
                    .append(t.getStartIndex()).append(',').append(t.getStopIndex()).append(',')
                    .append(t.getLine()).append(',').append(t.getCharPositionInLine());
        }
        Map<Class<?>, Integer> names = new HashMap<>();
        List<String> nameList = new ArrayList<>();
        StringBuilder tree = new StringBuilder();
        StringBuilder labels = new StringBuilder();
        int contexts = 0;
        ArrayDeque<ParseTree> stack = new ArrayDeque<>();
        stack.push(root);
        while (!stack.isEmpty()) {
            ParseTree node = stack.pop();
            if (tree.length() > 0) {
                tree.append(',');
            }
            if (node instanceof TerminalNode) {
                Token sym = ((TerminalNode) node).getSymbol();
                if (sym.getTokenIndex() < 0) {
                    throw new IllegalStateException("a token the parser made up");
                }
                tree.append(node instanceof ErrorNode ? -2 : -1).append(',').append(sym.getTokenIndex());
                continue;
            }
            ParserRuleContext ctx = (ParserRuleContext) node;
            Integer k = names.get(ctx.getClass());
            if (k == null) {
                k = nameList.size();
                names.put(ctx.getClass(), k);
                nameList.add(ctx.getClass().getSimpleName());
            }
            int n = ctx.getChildCount();
            tree.append(k).append(',').append(index(ctx.getStart())).append(',').append(stopIndex(all, ctx.getStop()))
                    .append(',').append(ctx.invokingState).append(',').append(ctx.exception != null ? 1 : 0)
                    .append(',').append(n);
            for (Field f : labelFields(ctx.getClass())) {
                labels.append(labels.length() == 0 ? "[" : ",[").append(contexts).append(',');
                str(labels, f.getName());
                Object v = f.get(ctx);
                if (v instanceof List) {
                    boolean tokensList = f.getGenericType().getTypeName().contains("Token");
                    labels.append(tokensList ? ",\"T\",[" : ",\"C\",[");
                    List<?> list = (List<?>) v;
                    for (int i = 0; i < list.size(); i++) {
                        labels.append(i == 0 ? "" : ",").append(tokensList ? index((Token) list.get(i)) : child(ctx, list.get(i)));
                    }
                    labels.append("]]");
                } else if (Token.class.isAssignableFrom(f.getType())) {
                    labels.append(",\"t\",").append(index((Token) v)).append(']');
                } else {
                    labels.append(",\"c\",").append(child(ctx, v)).append(']');
                }
            }
            contexts++;
            for (int i = n - 1; i >= 0; i--) {
                stack.push(ctx.getChild(i));
            }
        }
        b.append("],\"names\":[");
        for (int i = 0; i < nameList.size(); i++) {
            if (i > 0) {
                b.append(',');
            }
            str(b, nameList.get(i));
        }
        b.append("],\"tree\":[").append(tree).append("],\"labels\":[").append(labels).append(']');
    }

    /** A context's stop token as the Python runtime records it: Java's exitRule takes the EOF
     *  token once EOF was matched (LT(1)), Python's always LT(-1), the last token on the
     *  default channel before it. */
    static int stopIndex(List<Token> all, Token stop) {
        if (stop == null || stop.getType() != Token.EOF) {
            return index(stop);
        }
        for (int i = stop.getTokenIndex() - 1; i >= 0; i--) {
            if (all.get(i).getChannel() == Token.DEFAULT_CHANNEL) {
                return i;
            }
        }
        return -1;
    }

    static int index(Token t) {
        return t == null ? -1 : t.getTokenIndex();
    }

    /** The index of a labelled context among ctx's children (-1: null or not a child). */
    static int child(ParserRuleContext ctx, Object v) {
        if (v == null || ctx.children == null) {
            return -1;
        }
        for (int i = 0; i < ctx.children.size(); i++) {
            if (ctx.children.get(i) == v) {
                return i;
            }
        }
        return -1;
    }

    static String readLine(InputStream in) throws IOException {
        StringBuilder b = new StringBuilder();
        int c;
        while ((c = in.read()) != -1 && c != '\n') {
            b.append((char) c);
        }
        return c == -1 && b.length() == 0 ? null : b.toString();
    }

    public static void main(String[] args) throws Exception {
        Class<?> lexerCls = Class.forName("KRLLexer");
        Class<?> parserCls = Class.forName("KRLParser");
        lexerNew = lexerCls.getConstructor(org.antlr.v4.runtime.CharStream.class);
        parserNew = parserCls.getConstructor(TokenStream.class);
        startRule = parserCls.getMethod(args.length > 1 ? args[1] : "module");
        newlineType = (int) parserCls.getField("NEWLINE").get(null);
        parserClassName = parserCls.getName();
        int threads = args.length > 0 ? Integer.parseInt(args[0]) : 1;

        PrintStream out = new PrintStream(new BufferedOutputStream(System.out, 1 << 16), false, StandardCharsets.UTF_8);
        ThreadFactory big = r -> new Thread(null, r, "parse", 64L << 20);  // deep rule nesting
        ExecutorService pool = Executors.newFixedThreadPool(Math.max(1, threads), big);
        DataInputStream in = new DataInputStream(new java.io.BufferedInputStream(System.in, 1 << 16));
        String header;
        while ((header = readLine(in)) != null) {
            String[] parts = header.trim().split(" ");
            long id = Long.parseLong(parts[0]);
            int n = Integer.parseInt(parts[1]);
            boolean wantTree = false;
            int firstLine = 1;
            for (int k = 2; k < parts.length; k++) {
                if (parts[k].equals("t")) {
                    wantTree = true;
                } else if (parts[k].startsWith("L")) {
                    firstLine = Integer.parseInt(parts[k].substring(1));
                }
            }
            final boolean tree = wantTree;
            final int first = firstLine;
            if (n < 0) {
                break;
            }
            byte[] data = new byte[n];
            in.readFully(data);
            String text = new String(data, StandardCharsets.UTF_8);
            pool.execute(() -> {
                String answer;
                try {
                    answer = parse(id, text, tree, first);
                } catch (Throwable ex) {  // one bad file never stops the worker
                    Throwable cause = ex instanceof java.lang.reflect.InvocationTargetException ? ex.getCause() : ex;
                    StringBuilder b = new StringBuilder("{\"id\":").append(id).append(",\"fail\":");
                    str(b, String.valueOf(cause));
                    answer = b.append('}').toString();
                }
                synchronized (out) {
                    out.print(answer);
                    out.print('\n');
                    out.flush();
                }
            });
        }
        pool.shutdown();
        pool.awaitTermination(1, TimeUnit.HOURS);
        out.flush();
    }
}
