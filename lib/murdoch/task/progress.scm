;;;; What pose-task tells of its work, as it goes.

;;> A port on which pose-task tells what it is doing, or #f for silence.
(define pose-task-progress (make-parameter #f))

;; Received code that sets these sets them for its own call only.
(sandbox-parameter! pose-task-progress)

;;> Tells the line that \var{part}s make on (pose-task-progress), if any:
;;> the parts are evaluated only then, so that a silent negotiation does
;;> not build the lists it would have told of.
(define-syntax progress
  (syntax-rules ()
    ((progress part ...)
     (let ((out (pose-task-progress)))
       (if out (progress-line out (list part ...)))))))

(define (progress-line out parts)
  ;; One write-string a line, so lines from threads do not interleave.
  (write-string
   (call-with-output-string
     (lambda (line)
       (write-string "pose-task: " line)
       (for-each (lambda (p)
                   (if (string? p) (write-string p line) (write p line)))
                 parts)
       (newline line)))
   out)
  (flush-output-port out))
