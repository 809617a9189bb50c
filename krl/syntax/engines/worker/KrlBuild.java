// Generates (and for Java compiles) the parsers of many grammar versions in one JVM, so that
// `krl growth` and `krl validate` pay the JVM start and the JIT warm-up once, not per version
// (krl/syntax/engines/java.py build_many). Arguments: triples "<python|java> <KRL.g4> <out dir>".
// For each: the ANTLR tool with the same options as the one-off builds (python:
// -Dlanguage=Python3 -visitor -no-listener; java: -Dlanguage=Java -no-listener -no-visitor, then
// javac into <out dir>). Prints "ok <out dir>" or "fail <out dir> <reason>" per triple.

import java.io.ByteArrayOutputStream;
import java.io.File;
import java.io.PrintStream;
import java.nio.charset.StandardCharsets;

import javax.tools.JavaCompiler;
import javax.tools.ToolProvider;

import org.antlr.v4.Tool;

public final class KrlBuild {
    public static void main(String[] args) {
        String cp = System.getProperty("java.class.path");
        JavaCompiler javac = ToolProvider.getSystemJavaCompiler();
        for (int i = 0; i + 2 < args.length; i += 3) {
            String lang = args[i];
            File g4 = new File(args[i + 1]);
            File out = new File(args[i + 2]);
            try {
                File gen = lang.equals("java") ? new File(out, "gen") : out;
                String[] toolArgs = lang.equals("java")
                        ? new String[] {"-Dlanguage=Java", "-no-listener", "-no-visitor", "-Xexact-output-dir",
                                        "-o", gen.getPath(), g4.getPath()}
                        : new String[] {"-Dlanguage=Python3", "-visitor", "-no-listener", "-Xexact-output-dir",
                                        "-o", gen.getPath(), g4.getPath()};
                Tool tool = new Tool(toolArgs);
                tool.processGrammarsOnCommandLine();
                if (tool.getNumErrors() > 0) {
                    System.out.println("fail " + out + " the ANTLR tool reported " + tool.getNumErrors() + " errors");
                    continue;
                }
                if (lang.equals("java")) {
                    if (javac == null) {
                        System.out.println("fail " + out + " no Java compiler in this JVM (a JDK is needed)");
                        continue;
                    }
                    ByteArrayOutputStream err = new ByteArrayOutputStream();
                    int rc = javac.run(null, null, new PrintStream(err, true, StandardCharsets.UTF_8),
                            "-nowarn", "-encoding", "UTF-8", "-cp", cp, "-d", out.getPath(),
                            new File(gen, "KRLLexer.java").getPath(), new File(gen, "KRLParser.java").getPath());
                    if (rc != 0) {
                        String msg = err.toString(StandardCharsets.UTF_8).replace('\n', ' ');
                        System.out.println("fail " + out + " javac: " + msg.substring(0, Math.min(400, msg.length())));
                        continue;
                    }
                }
                System.out.println("ok " + out);
            } catch (RuntimeException ex) {
                System.out.println("fail " + out + " " + ex);
            }
            System.out.flush();
        }
    }
}
