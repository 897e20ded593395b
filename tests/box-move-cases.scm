;;; The cases of the box team (examples/box-move.scm, docs/box-move.md),
;;; included by tests/box-move*-test.scm, one case each, which tests/run
;;; runs one by one: each case is
;;; `make demo-box`'s run, in the lab's fast-forward simulator, on a port
;;; base of its own, judged by examples/box-judge.scm from the simulator's
;;; own word: the box must end within 300 mm of the path's goal and 20
;;; degrees of its heading, and with a fault the spare, the robot the lost
;;; pusher's component went to, must have been at the box's rear face for
;;; the last third of the distance the box moved.  A lab with no spare
;;; (box-case's third argument #f) is judged by where the box ended, and
;;; the task must say that the lost pusher's component failed with no
;;; other robot to take it.  The including file imports what it needs.

;; The demo's output, and whether it exited 0, for LAB (relative to the
;; top, or absolute) with FAULT ("" for none, or a role: inside, outside),
;; killed after (seconds after step 1 is done; default 3).  Its robots steer
;; in real time against the simulator's clock, so it runs ahead of the tests
;; beside it (nice -10, as root; as another user nice says it cannot, and
;; the demo runs as usual): two runs of the suite at once once left the
;; spare of FAULT=2 too late at the box.
(define (run-demo lab fault . after)
  (let* ((dir (temporary-directory)) (out (string-append dir "/demo.out"))
         (status
          (system? "sh" "-c"
                   (string-append
                    "cd \"$0\" && MURDOCH_PORT_BASE=$1 MURDOCH_DEMO_FAULT=$4 MURDOCH_DEMO_FAULT_AFTER=$6"
                    " MURDOCH_DEMO_TASK=\"$2/examples/pose-box-move.scm\""
                    " MURDOCH_DEMO_JUDGE=\"$2/examples/box-judge.scm\""
                    " nice -n -10 timeout -s KILL 280 \"$2/bin/murdoch\" demo \"$5\" >\"$3\" 2>&1")
                   dir (number->string (free-port-base dir)) (tool-path ".") out
                   fault (if (char=? (string-ref lab 0) #\/) lab (tool-path lab))
                   (number->string (if (pair? after) (car after) 3))))
         (text (file-text out)))
    (delete-file-hierarchy dir)
    (cons status text)))

;; Draws seed's layout (tools/box-layout.scm) into a fresh folder: the
;; folder and the generator's words, or #f and its words when it refused.
(define (generated-layout seed)
  (let* ((dir (temporary-directory)) (out (string-append dir "/layout.out"))
         (ok? (system? "sh" "-c" "\"$0\" \"$1\" \"$2\" \"$3\" >\"$4\" 2>&1"
                       (tool-path "tools/chibi") (tool-path "tools/box-layout.scm")
                       (number->string seed) dir out)))
    (cons (and ok? dir) (file-text out))))

;; The number after "box-layout: fault ROLE after" in a layout's words.
(define (layout-fault words)
  (any (lambda (line)
         (let ((prefix "box-layout: fault "))
           (and (text-contains? line prefix)
                (let ((in (open-input-string
                           (substring line (string-length prefix) (string-length line)))))
                  (let* ((role (read in)) (after (begin (read in) (read in))))
                    (list (symbol->string role) after))))))
       (text-lines words)))

;; The number after "bench: NAME " in text, or #f.
(define (bench text name)
  (let ((prefix (string-append "bench: " name " ")))
    (any (lambda (line)
           (and (>= (string-length line) (string-length prefix))
                (string=? prefix (substring line 0 (string-length prefix)))
                (read (open-input-string (substring line (string-length prefix)
                                                    (string-length line))))))
         (text-lines text))))

;; One case: LAB's demo with FAULT, its assertions in a group of their own;
;; spare? (by default #t) whether LAB has a robot to take a lost pusher's
;; place; after, when the fault comes (run-demo).
(define (box-case lab fault . options)
  (let* ((spare? (or (null? options) (car options)))
         (run (apply run-demo lab fault (if (and (pair? options) (pair? (cdr options)))
                                            (cdr options)
                                            '())))
         (status (car run)) (text (cdr run))
         (name (if (string=? fault "") "box-move" "box-move-fault")))
    (test-group (string-append lab (if (string=? fault "")
                                       ""
                                       (string-append ", " fault " pusher killed")))
      (test "the box arrives: within 300 mm of the goal and 20 degrees of its heading" #t
        (text-contains? text "within 300 mm and 20 degrees"))
      (test-assert "its goal error, a bench line, is at most 300 mm"
        (let ((mm (bench text (string-append name "-goal-error-mm"))))
          (and (real? mm) (<= mm 300))))
      (test-assert "both steps ran, the second to its end"
        (text-contains? text ": step 2 done: ("))
      (if (not (string=? fault ""))
          (test-assert "a pusher was killed"
            (text-contains? text "demo: FAULT: killing ")))
      (cond ((string=? fault ""))
            (spare?
             (test-assert "its component went to a spare"
               (text-contains? text " reassigned from "))
             (test "the spare pushed for the last third of the way" #t
               (text-contains? text ": it pushed"))
             (test-assert "box-move-spare-push-mm, a bench line, is above nought"
               (let ((mm (bench text "box-move-spare-push-mm")))
                 (and (real? mm) (> mm 0)))))
            (else
             (test-assert "the task says the lost pusher's part failed, no robot left"
               (text-contains? text "connection lost; no other capable robot is free"))
             (test-assert "the other pusher finished its part of step 2"
               (let ((done (find (lambda (line) (text-contains? line ": step 2 done: "))
                                 (text-lines text)))
                     (other (if (string=? fault "inside") " outside)" " inside)")))
                 (and done (text-contains? done other))))))
      ;; With no spare the task fails, as it must, for one of its parts did.
      (test "the demo says so by its exit status" spare? status))
    (if (not (and (eq? status spare?) (text-contains? text "within 300 mm and 20")))
        (show-failed-run text))))

;; A generated layout's case (tools/box-layout.scm): seed's lab, with its
;; fault (its role and time) when fault? is true.
(define (generated-box-case seed fault?)
  (let* ((made (generated-layout seed)) (dir (car made)))
    (test-group (string-append "seed " (number->string seed))
      (test-assert "tools/box-layout.scm draws a layout" dir)
      (display (cdr made))
      (if dir
          (let ((fault (layout-fault (cdr made))))
            (if fault?
                (box-case (string-append dir "/lab.scm") (car fault) #t (cadr fault))
                (box-case (string-append dir "/lab.scm") ""))
            (delete-file-hierarchy dir))))))

;; A failed run's output, its judge's verdict first: tests/run shows only
;; a few lines after a failure.
(define (show-failed-run text)
  (newline)
  (for-each (lambda (line)
              (if (text-contains? line "box-move: ") (begin (display line) (newline))))
            (text-lines text))
  (display text))
