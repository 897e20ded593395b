;;> The callee's side of the wire: accepting connections, reading calls,
;;> running them, and the janitor that ends stalled connections and
;;> relieves readers held by a long apply.

(define-library (murdoch serve)
  (export start-serving! frame-timeout
          new-serving! read-as-reader reader? read-calls serve-call
          serving-read-on serving-read-on-set!)
  (import (scheme base) (srfi 1) (srfi 18)
          (only (chibi filesystem) open-input-file-descriptor
                open-output-file-descriptor)
          (chibi net) (chibi match)
          (murdoch scheduler) (murdoch wait) (murdoch log) (murdoch abandon)
          (murdoch remote-error) (murdoch netstring) (murdoch frame)
          (only (murdoch connect) socket-port)
          (murdoch lab) (murdoch sendable) (murdoch sandbox)
          (murdoch aspace) (murdoch worker) (murdoch call))
  (include "serve.scm"))
