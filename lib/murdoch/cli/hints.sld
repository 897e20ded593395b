;;> What the REPL adds to an error a person's own mistake caused: the
;;> error as theirs, and a hint for a newcomer's first mistakes.

(define-library (murdoch cli hints)
  (export eval-with-hints)
  (import (scheme base) (scheme eval)
          (only (chibi) make-exception exception? exception-kind identifier?
                identifier->symbol)
          (only (chibi edit-distance) edit-distance)
          (only (murdoch remote) known-uids)
          (only (chibi ast) exception-source procedure-arity procedure-variadic?
                procedure-name)
          (murdoch wire) (only (murdoch code) send-error? visible-names nearest-name))
  (include "hints.scm"))
