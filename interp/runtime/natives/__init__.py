"""The simulator's implementations of KRL's system functions (being gathered here from
interp/runtime/builtins.py, issue 47): ``eki`` holds the EthernetKRL and RSI natives."""
