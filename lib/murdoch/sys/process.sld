;;> \procedure{(set-process-name! name)} Names this process for ps and
;;> top (cut to 15 bytes): an address space is murdoch-UID.
;;> \procedure{(set-parent-death-signal! signal)} Has the kernel send
;;> \var{signal} to this process when the thread that forked it ends.
;;> Both answer #f when the kernel refuses.  Body: process.stub.
;;> \procedure{(die-with-parent! parent signal)} In a child just forked by
;;> process \var{parent}: \var{signal} comes when the parent ends, and the
;;> child exits at once if the parent ended before it asked.
(define-library (murdoch sys process)
  (export set-process-name! set-parent-death-signal! die-with-parent!)
  (import (scheme base) (scheme process-context) (only (chibi process) parent-process-id))
  (include-shared "process")
  (begin
    (define (die-with-parent! parent signal)
      (set-parent-death-signal! signal)
      (if (not (= (parent-process-id) parent)) (exit 1)))))
