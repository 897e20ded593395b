;;> Scripted REPL sessions (docs/transcripts.md): reading transcripts or a
;;> document's sessions, replaying them against a fresh lab, comparing.
(define-library (murdoch testing transcript)
  (export read-transcript read-doc-transcript transcript-lab transcript-as
          transcript-steps
          transcript-shell transcript-script
          prompt-count transcript-mismatches line-matches? check-transcript)
  (import (scheme base) (scheme char) (scheme file) (scheme write) (srfi 1)
          (chibi test)
          (only (chibi filesystem) delete-file-hierarchy)
          (only (chibi process) system? call-with-process-io waitpid)
          (only (murdoch testing harness) read-lines free-port-base start-murdoch-lab!
                tool-path
                file-text wait-until temporary-directory stop-process!))
  (include "transcript.scm"))
