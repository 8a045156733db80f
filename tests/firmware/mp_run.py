# Runs test modules under MicroPython: micropython mp_run.py test_protocol test_config ...
# Prints one line per test and a final "RESULT <passed> <failed>".
import sys

passed = 0
failed = 0
for name in sys.argv[1:]:
    mod = __import__(name)
    for attr in sorted(dir(mod)):
        if not attr.startswith("test_"):
            continue
        try:
            getattr(mod, attr)()
            passed += 1
            print("PASS", name, attr)
        except Exception as e:
            failed += 1
            print("FAIL", name, attr, repr(e))
            sys.print_exception(e)
print("RESULT", passed, failed)
