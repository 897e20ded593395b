;;; The REPL sessions of docs/tutorial.md and README.md, replayed as they
;;; are written there (read-doc-transcript, docs/transcripts.md), so that
;;; neither drifts from the code.  Apart from transcripts-test, whose
;;; files fill its time.
(import (scheme base) (chibi test) (murdoch testing harness) (murdoch testing transcript))

(test-begin "docs-transcripts")
(for-each (lambda (doc)
            (check-transcript doc (read-doc-transcript (tool-path doc))))
          '("docs/tutorial.md" "README.md"))
(test-end)
(test-exit)
