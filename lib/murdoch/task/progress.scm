;;;; What pose-task tells of its work, as it goes.

;;> A port on which pose-task tells what it is doing, or #f for silence.
(define pose-task-progress (make-parameter #f))

;; Received code that sets these sets them for its own call only.
(sandbox-parameter! pose-task-progress)

(define (progress . parts)
  (let ((out (pose-task-progress)))
    (when out
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
      (flush-output-port out))))
