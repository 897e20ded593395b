;;;; Status: each address space says how it is, and the lab's status is
;;;; what they all say, asked at once.

;;> What this address space says of itself: (UID UP-SINCE POSE BATTERY
;;> HELD TASKS GOAL ENDED HANDED), read by the report- procedures: POSE
;;> as safe-reckon, BATTERY in tenths of a volt, HELD (subject holder)
;;> entries, TASKS, ENDED and HANDED as (tasks), (components-ended) and
;;> (handed-entries) answer, GOAL goto-xy's or #f.
(define (aspace-report)
  ;; The components running are read before those ended: one that ends
  ;; in between is then in both lists, never in neither.
  (let* ((all (tasks))
         (over? (lambda (t) (and (listed-posed? t)
                                 (memq (listed-state t)
                                       '(done failed cancelled deadline let-go)))))
         (over (filter over? all))
         (shown (append (remove over? all)
                        (if (> (length over) over-shown) (take over over-shown) over)))
         (ended (components-ended)))
    (list (local-aspace-uid) (aspace-started-at) (safe-reckon)
          (safe-battery-voltage)
          (filter (lambda (h) (not (null? (held-holder h))))
                  (subscription-statuses '>))
          shown (goto-goal) ended (handed-entries))))

;;> The parts of an aspace-report \var{r}, by name.
(define (report-uid r) (car r))
(define (report-since r) (cadr r))
(define (report-pose r) (list-ref r 2))
(define (report-battery r) (list-ref r 3))
(define (report-held r) (list-ref r 4))
(define (report-tasks r) (list-ref r 5))
;; A report from a peer older than GOAL, or ENDED, has none.
(define (report-goal r) (and (> (length r) 6) (list-ref r 6)))
(define (report-ended r) (if (> (length r) 7) (list-ref r 7) '()))
(define (report-handed r) (if (> (length r) 8) (list-ref r 8) '()))

;; How many of its tasks that are over an address space's report shows.
(define over-shown 5)

;;> The subject and its holder in \var{h}, one of a report's HELD.
(define (held-subject h) (car h))
(define (held-holder h) (cadr h))

(define (make-away uid why) (list uid 'away why))
(define (away? r) (eq? (cadr r) 'away))
(define (away-why r) (car (cddr r)))

;;> The lab's status: for each address space of \var{lab}, in file order,
;;> its report (see aspace-report) when it answered within
;;> (remote-timeout) seconds, else (UID away WHY).
(define (lab-status lab)
  (map (lambda (o)
         (if (outcome-ok? o)
             (outcome-value o)
             (make-away (outcome-uid o) (outcome-value o))))
       (remote-apply-all (map (lambda (a) (uid->aspace (lab-aspace-uid a)))
                              (lab-aspaces lab))
                         aspace-report)))

;;> Writes the status of the lab this address space is in (see
;;> lab-status) as a person reads it: a line per address space, then one
;;> per subject held.
(define (show-status . port)
  (apply write-lab-status port)
  (if #f #f))

;;> show-status, answering how many address spaces answered: `murdoch
;;> status` exits 1 when none did.
(define (write-lab-status . port)
  (let* ((status (lab-status (current-lab)))
         (line (lab-line))
         (out (if (pair? port) (car port) (current-output-port))))
    (display-lab-status status line (utc-seconds) out)
    (count (lambda (r) (not (away? r))) status)))

;;> Every task of the lab that waits its turn, whoever posed it (a guest
;;> too), best-ranked first: (POSER PLACE ENTRY), PLACE its place in the
;;> lab's line, 1 to n, ENTRY as (tasks) lists it.
(define (lab-line)
  (let ((all (guard (e (#t '()))
               (append-map (lambda (answer)
                             (map (lambda (e) (cons (car answer) e)) (cadr answer)))
                           (request 'waiting-tasks waiting-entries)))))
    ;; Each element is (POSER RANK . ENTRY).
    (map (lambda (x place) (list (car x) place (cddr x)))
         (list-sort (lambda (a b) (rank<? (cadr a) (cadr b))) all)
         (iota (length all) 1))))

(define (in-line line id)
  (find (lambda (x) (eq? (listed-id (car (cddr x))) id)) line))

;; Each address space's report, its waiting tasks as the line has them;
;; then the waiting tasks of guests, posers that are not of the lab.
(define (display-lab-status status line now out)
  (for-each (lambda (r) (write-report r line now out)) status)
  (let ((guests (remove (lambda (x) (any (lambda (r) (eq? (report-uid r) (car x))) status))
                        line)))
    (for-each (lambda (poser)
                (write-line out (symbol->string poser) "  a guest of the lab")
                (for-each (lambda (x)
                            (if (eq? (car x) poser)
                                (write-line out "    " (task-text (car (cddr x))
                                                                  (cadr x)))))
                          guests))
              (delete-duplicates (map car guests)))))

(define (write-report r line now out)
  (let ((uid (symbol->string (report-uid r))))
    (cond
     ((away? r)
      (write-line out uid "  away: " (away-why r)))
     (else
      (write-line out uid "  up " (seconds-text (- now (report-since r))) " s"
                  (pose-text (report-pose r))
                  "  battery " (tenths-text (report-battery r)))
      (for-each (lambda (held)
                  (write-line out "    " (symbol->string (held-subject held))
                              " held by " (held-text (held-holder held))))
                (report-held r))
      (for-each (lambda (t)
                  (write-line out "    "
                              (task-text t (and (listed-posed? t)
                                                (cond ((in-line line (listed-id t)) => cadr)
                                                      (else (listed-place t)))))))
                (report-tasks r))
      (for-each (lambda (e) (write-line out "    " (handed-text e)))
                (report-handed r))))))

(define (handed-text e)
  (string-append
   (case (lab-task-role e)
     ((coordinator) "coordinates detached task ")
     ((standby) "stands by for detached task ")
     (else "let go of detached task "))
   (held-text (lab-task-id e)) " " (held-text (lab-task-state e))
   (if (eq? (lab-task-role e) 'standby)
       (string-append ", coordinated by " (held-text (lab-task-coordinator e)))
       (string-append ", standby " (held-text (or (lab-task-standby e) "none"))))))

;;> An entry of lab-tasks as `murdoch tasks` writes it: the task's id,
;;> state, coordinator, standby and poser, and when a standby took it
;;> over.
(define (lab-task-line e)
  (string-append (held-text (lab-task-id e)) "  " (held-text (lab-task-state e))
                 "  coordinator " (held-text (lab-task-coordinator e))
                 "  standby " (held-text (or (lab-task-standby e) "none"))
                 "  posed by " (held-text (lab-task-poser e))
                 (if (lab-task-took-over e) "  (taken over)" "")))

(define (task-text t place)
  (if (listed-posed? t)
      (string-append "task " (held-text (listed-id t)) " " (held-text (listed-state t))
                     (cond ((memq (listed-state t) '(waiting holding))
                            (string-append ": " (join-text (cons (waiting-text t place)
                                                                 (or (listed-why t) '())))))
                           ((listed-why t) => (lambda (why) (string-append ": " why)))
                           (else "")))
      (string-append "runs component " (held-text (listed-index t)) " of "
                     (held-text (listed-id t)) " for " (held-text (listed-poser t)))))

;;> What a waiting task's entry \var{t} of (tasks) says, at \var{place} in
;;> the lab's line: "holds lifter2; waits for 1 more (mobile lift); 2nd
;;> in line; priority 0".  The status adds why it waits.
(define (waiting-text t place)
  (let ((held (listed-held t)) (wants (listed-wants t)))
    (join-text
     (append
      (if (pair? held)
          (list (string-append "holds " (words-text held)))
          '())
      (list (string-append "waits for " (number->string (length wants))
                           (if (pair? held) " more" "")
                           " (" (join-with ", " (map capability-text wants)) ")")
            (if place (string-append (ordinal place) " in line") "not in line yet")
            (string-append "priority " (held-text (listed-priority t))))))))

;; A component's capabilities, (EXCLUSIVE SHARED) or a list of subjects,
;; as their subjects' names: "mobile lift".
(define (capability-text caps)
  (words-text (if (and (pair? caps) (every list? caps)) (apply append caps) caps)))

(define (words-text xs) (join-with " " (map held-text xs)))

(define (join-with sep strings)
  (if (null? strings)
      ""
      (fold (lambda (s acc) (string-append acc sep s)) (car strings) (cdr strings))))

(define (ordinal n)
  (string-append (number->string n)
                 (cond ((memv (modulo n 100) '(11 12 13)) "th")
                       ((= (modulo n 10) 1) "st")
                       ((= (modulo n 10) 2) "nd")
                       ((= (modulo n 10) 3) "rd")
                       (else "th"))))

(define (join-text strings) (join-with "; " strings))

(define (write-line out . parts)
  (for-each (lambda (p) (write-string p out)) parts)
  (newline out))

(define (seconds-text s) (number->string (exact (round s))))

(define (pose-text pose)
  (if pose
      (string-append "  at (" (number->string (exact (round (car pose)))) " "
                     (number->string (exact (round (cadr pose)))) ") heading "
                     (number->string (exact (round (car (cddr pose))))))
      ""))

(define (tenths-text tenths) (string-append (number->string (/ tenths 10.)) " V"))

(define (held-text holder)
  (let ((out (open-output-string)))
    (display holder out)
    (get-output-string out)))
