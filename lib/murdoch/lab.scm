;;;; The lab file (docs/lab-file.md): who is in the lab and where.
;;
;; Every peer reads the same file, so the lab needs no registry: a uid
;; names an address space, and the file says where it listens.

(define-record-type lab
  (make-lab name directory settings aspaces clauses)
  lab?
  (name lab-name)
  (directory lab-directory)
  (settings lab-settings)
  (aspaces lab-aspaces)
  (clauses lab-clauses))

;;> The radius of the lab's robots in millimetres: its b14 clause's, or
;;> the simulator's B14's (room.scm).
(define (lab-robot-radius lab)
  (robot-radius (lab-clauses lab)))

;;> The lab file's top-level clause \scheme{(key ...)}, such as its
;;> \scheme{world}, or #f.
(define (lab-clause lab key)
  (clause key (lab-clauses lab)))

;;> One address space of the lab file.  \var{clauses} keeps the clauses that
;;> later layers read (robot, position, capabilities, load); \var{form} is
;;> its whole (aspace NAME ...) clause, for errors to name with its line.
(define-record-type lab-aspace
  (make-lab-aspace uid index host port clauses form)
  lab-aspace?
  (uid lab-aspace-uid)
  (index lab-aspace-index)
  (host lab-aspace-host)
  (port lab-aspace-port)
  (clauses lab-aspace-clauses)
  (form lab-aspace-form))

(define (clause key clauses)
  (find (lambda (c) (and (pair? c) (eq? (car c) key))) clauses))

(define (clause-value key clauses default)
  (cond ((clause key clauses) => cadr) (else default)))

;;; Settings
;;
;; Every setting a lab file may give, in one table: its name, its
;; default, and its reader.  Most take one value; code and delivery take
;; the rest of their clause.  read-lab reads each once, and every place
;; that needs one asks lab-setting.

(define-record-type setting
  (make-setting name default reader)
  setting?
  (name setting-name)
  (default setting-default)
  (reader setting-reader))

;; What a clause's value may be: read answers the value to use for what
;; the file wrote, or #f when that will not do, and what says what will.
(define-record-type reader
  (make-reader read what)
  reader?
  (read reader-read)
  (what reader-what))

(define (number-over zero what)
  (make-reader (lambda (x) (and (real? x) (> x zero) x)) what))

(define (whole-from low high what)
  (make-reader (lambda (x) (and (exact-integer? x) (<= low x high) x)) what))

(define (text what) (make-reader (lambda (x) (and (string? x) x)) what))

(define seconds (number-over 0 "a positive number of seconds"))
(define rate
  (make-reader (lambda (x) (and (real? x) (>= x 0) x)) "a number, 0 or more, per second"))
(define positive-count (whole-from 1 1000000000 "a positive whole number"))

;; A size: bytes, or a string of a number and K, M or G.
(define (size-bytes size)
  (cond ((and (exact-integer? size) (positive? size)) size)
        ((and (string? size) (> (string-length size) 1))
         (let* ((n (string-length size))
                (unit (assv (string-ref size (- n 1))
                            '((#\K . 1024) (#\M . 1048576) (#\G . 1073741824))))
                (number (string->number (substring size 0 (- n 1)))))
           (and unit number (positive? number) (exact (round (* number (cdr unit)))))))
        (else #f)))

(define (delivery-clause args)
  (cond ((equal? args '(broadcast)) args)
        ((and (pair? args) (eq? (car args) 'multicast) (pair? (cdr args))
              (string? (cadr args))
              (or (null? (cddr args))
                  (and (exact-integer? (car (cddr args))) (null? (cdr (cddr args))))))
         args)
        (else #f)))

(define setting-entries
  `((port-base 7100 ,(whole-from 1 65535 "a port number"))
    ;; sim/lab.c keeps an interface, and a robot's name, in 64 bytes.
    (interface "127.0.0.1"
               ,(make-reader
                 (lambda (x) (and (string? x) (< (string-length x) 64) x))
                 "an IPv4 address, in quotes"))
    (key-file "murdoch.key" ,(text "a file name, in quotes"))
    (max-frame 1048576 ,positive-count)
    ;; Chibi's writer cuts what nests deeper than 10,000 (sendable.scm).
    (max-depth 4000 ,(whole-from 1 9000 "a whole number from 1 to 9000"))
    (timeout 5 ,seconds)
    ;; At a REPL a person waits, and Ctrl-C gives a call up: a robot's
    ;; motion there runs to its end (command.scm).
    (repl-timeout 600 ,seconds)
    (frame-timeout 5 ,seconds)
    (lease 30 ,seconds)
    (monitor-period 60 ,seconds)
    ;; A started task's components and their poser hear from each other
    ;; every heartbeat seconds (task/life-cycle.scm).
    (heartbeat 0.5 ,seconds)
    (max-attempts 3 ,positive-count)
    ;; A started task that finds too few capable robots free waits for
    ;; them or fails with not-enough-takers; its priority rises by aging
    ;; a second while it waits; a poser keeps at most max-waiting such
    ;; tasks (task/life-cycle.scm, docs/tasks.md).
    (when-robots-busy fail
                      ,(make-reader (lambda (x) (and (memq x '(fail wait)) x))
                                    "fail or wait"))
    (aging 0.1 ,rate)
    (max-waiting 100 ,positive-count)
    ;; A poser's (tasks) keeps the newest tasks-kept of its tasks that are
    ;; over, and forgets the others (task/record.scm).
    (tasks-kept 20 ,(whole-from 0 1000000 "a whole number, 0 or more"))
    (max-connections 256 ,positive-count)
    (max-connections-per-host 64 ,positive-count)
    (heap-max "512M" ,(make-reader size-bytes
                                   "bytes, or a size in quotes such as \"512M\""))
    ;; Chibi grows its heap by twice one allocation (sandbox.scm).
    (max-alloc "32M" ,(make-reader size-bytes
                                   "bytes, or a size in quotes such as \"32M\""))
    (code () ,(make-reader (lambda (x) (and (every string? x) x))
                           "file names, in quotes"))
    (delivery (broadcast)
              ,(make-reader delivery-clause
                            "broadcast, or multicast \"GROUP\" [PORT]"))))

(define settings-table
  (map (lambda (entry) (apply make-setting entry)) setting-entries))

;; The clauses the simulator reads (docs/trip-protocol.md), and address
;; spaces.
(define other-clauses '(world simulator b14 aspace))

;;; Within aspace, robot, world, simulator and b14
;;
;; What each may hold, as the address spaces and sim/lab.c read it: for
;; each name, a reader of the clause's values, the list after its name;
;; a robot's values are clauses of their own, in a table.

(define (values-of n check what)
  (make-reader (lambda (xs) (and (= (length xs) n) (every check xs))) what))

(define (reals low high what)
  (make-reader (lambda (xs) (and (<= low (length xs) high) (every real? xs))) what))

(define (positive-real? x) (and (real? x) (positive? x)))

;; As reals, where the values at the places given, when there, are above 0:
;; a size or a mass (Box2D takes a negative one without a word).
(define (sized-reals low high places what)
  (make-reader (lambda (xs)
                 (and (<= low (length xs) high) (every real? xs)
                      (every (lambda (i)
                               (or (>= i (length xs)) (positive? (list-ref xs i))))
                             places)))
               what))

(define (non-negative? x) (and (real? x) (>= x 0)))
(define (port-number? x) (and (exact-integer? x) (< 0 x 65536)))

(define (load-value? x)
  (or (non-negative? x)
      (and (list? x) (pair? x)
           (every (lambda (p) (and (list? p) (= (length p) 2) (every non-negative? p)))
                  x))))

(define robot-table
  `((pose . ,(reals 3 3 "x y heading, three numbers (mm, mm, degrees)"))
    (tethered . ,(values-of 1 boolean? "#t or #f"))
    (battery . ,(values-of 1 positive-real? "volts, a positive number"))
    (trip-port . ,(values-of 1 port-number? "a port number"))
    (trip-host . ,(values-of 1 string? "an IPv4 address, in quotes"))))

(define aspace-table
  `((port . ,(values-of 1 port-number? "a port number"))
    (host . ,(values-of 1 string? "an IPv4 address, in quotes"))
    (robot . ,robot-table)
    (position . ,(reals 3 3 "x y heading, three numbers (mm, mm, degrees)"))
    (capabilities . ,(make-reader (lambda (xs) (every symbol? xs)) "subjects, as names"))
    (load . ,(values-of 1 load-value? "a number, or ((SECONDS LOAD) ...)"))))

(define world-table
  `((wall . ,(sized-reals 4 5 '(4) (string-append "x1 y1 x2 y2 and a thickness if not 50:"
                                                  " four or five numbers, the thickness"
                                                  " above 0")))
    (box . ,(sized-reals 5 6 '(2 3 5)
                         (string-append "x y width depth heading and a mass if not 5:"
                                        " five or six numbers, width, depth and mass"
                                        " above 0")))
    (friction . ,(values-of 1 non-negative? "a number"))))

(define simulator-table
  `((step-hz . ,(values-of 1 (lambda (x) (and (real? x) (>= x 1))) "a number from 1"))
    (seed . ,(values-of 1 real? "a number"))
    (speed . ,(values-of 1 (lambda (x) (or (positive-real? x) (eq? x 'fast)))
                          "a positive number, or fast"))
    (stall-timeout . ,(values-of 1 positive-real? "a positive number of seconds"))))

(define (increasing-pair)
  (make-reader (lambda (xs)
                 (and (= (length xs) 2) (every real? xs) (< (car xs) (cadr xs))))
               "two numbers, the first the smaller"))

(define b14-table
  `(,@(map (lambda (name) `(,name . ,(values-of 1 non-negative? "a number, 0 or more")))
           '(radius mass max-speed max-turn speed turn-speed sonar-cone sonar-noise
             sonar-hz ir-range fiducial-range battery-drain battery-idle battery-charge))
    (sonar-range . ,(increasing-pair))
    (battery-range . ,(increasing-pair))
    (fiducial-fov . ,(values-of 1 (lambda (x) (and (real? x) (< 0 x) (<= x 360)))
                                 "degrees, above 0 and at most 360"))
    (sonar-rays . ,(values-of 1 (lambda (x) (and (exact-integer? x) (<= 1 x 16)))
                               "a whole number from 1 to 16"))
    (max-frame . ,(values-of 1 (lambda (x) (and (exact-integer? x) (<= 64 x 65536)))
                              "a whole number from 64 to 65536"))))

;; Each of the items of clause c against table.
(define (check-within path c items table)
  (for-each (lambda (item) (check-item path c item table)) items))

(define (check-item path outer item table)
  (cond
   ((not (and (pair? item) (symbol? (car item)) (list? item)))
    (lab-file-error path outer (string-append (clause-text item) " is not a clause"
                                              " (NAME VALUE ...)")))
   ((assq (car item) table)
    => (lambda (entry)
         (let ((reader (cdr entry)))
           (cond ((not (reader? reader)) (check-within path item (cdr item) reader))
                 ((not ((reader-read reader) (cdr item)))
                  (lab-file-error path item
                                  (string-append (symbol->string (car item))
                                                 " takes " (reader-what reader))))))))
   (else
    (lab-file-error path item
                    (string-append "no such clause in " (symbol->string (car outer))
                                   (did-you-mean (car item) (map car table)))))))

;; A top-level clause that holds clauses of its own.
(define (check-inside path c)
  (case (car c)
    ((aspace)
     (if (not (and (pair? (cdr c)) (symbol? (cadr c))))
         (lab-file-error path c "an address space is (aspace NAME CLAUSE ...)"))
     (if (>= (string-length (symbol->string (cadr c))) 64)
         (lab-file-error path c "an address space's name is at most 63 characters"))
     (check-within path c (cddr c) aspace-table))
    ((world) (check-within path c (cdr c) world-table))
    ((simulator) (check-within path c (cdr c) simulator-table))
    ((b14) (check-within path c (cdr c) b14-table))))

(define multi-valued '(code delivery))

;;> The value of setting \var{key} of the lab: what its file says, or the
;;> default (docs/lab-file.md).
(define (lab-setting lab key)
  (cond ((assq key (lab-settings lab)) => cdr)
        (else (error "lab-setting: no such setting" key))))

;; The settings of the clauses, every one of the table's, checked: an
;; error names the file, the clause and what is wrong.
(define (read-settings path clauses)
  (for-each (lambda (c) (check-clause path c)) clauses)
  (map (lambda (s)
         (let ((c (clause (setting-name s) clauses)))
           (cons (setting-name s)
                 (if c
                     (setting-value path c s)
                     ((reader-read (setting-reader s)) (setting-default s))))))
       settings-table))

(define (check-clause path c)
  (if (not (and (pair? c) (symbol? (car c)) (list? c)))
      (lab-file-error path c "a clause is (NAME VALUE ...)"))
  (if (not (or (setting-named (car c)) (memq (car c) other-clauses)))
      (lab-file-error path c (string-append "no such setting"
                                            (did-you-mean (car c)
                                                          (append (map setting-name
                                                                       settings-table)
                                                                  other-clauses)))))
  (check-inside path c))

(define (setting-named name)
  (find (lambda (s) (eq? (setting-name s) name)) settings-table))

(define (setting-value path c s)
  (let* ((read (reader-read (setting-reader s)))
         (value (cond ((memq (setting-name s) multi-valued) (read (cdr c)))
                      ((and (pair? (cdr c)) (null? (cddr c))) (read (cadr c)))
                      (else #f))))
    (or value
        (lab-file-error path c (string-append (symbol->string (car c)) " takes "
                                              (reader-what (setting-reader s)))))))

(define (did-you-mean name names)
  (let ((near (find-nearest-edits (symbol->string name) (map symbol->string names))))
    (if (and (pair? near) (<= (edit-distance (symbol->string name) (car near)) 3))
        (string-append "; did you mean " (car near) "?")
        "")))

;; Where each list of the lab file being read starts: ((LIST . LINE) ...),
;; by eq?, for its errors.
(define clause-lines (make-parameter '()))

(define (clause-line c)
  (cond ((assq c (clause-lines)) => cdr) (else #f)))

;; An error that names the file, the line of clause c, c shortened to one
;; line, and why.
(define (lab-file-error path c why)
  (let ((line (clause-line c)))
    (error (string-append path (if line (string-append ":" (number->string line)) "")
                          ": " (clause-text c) ": " why))))

;; c as written, on one line, cut at 60 characters.
(define (clause-text c)
  (let* ((out (open-output-string))
         (text (begin (write c out) (get-output-string out))))
    (if (> (string-length text) 60)
        (string-append (substring text 0 56) " ...")
        text)))

;;> The clause \scheme{(key ...)} of an address space, or #f.
(define (lab-aspace-clause a key)
  (clause key (lab-aspace-clauses a)))

;;> The lab's port base: MURDOCH_PORT_BASE, else its port-base.
(define (lab-port-base lab)
  (settings-port-base (lab-settings lab)))

;;> The port base where no lab file is read (murdoch replay):
;;> MURDOCH_PORT_BASE, else port-base's default.
(define (unread-lab-port-base)
  (settings-port-base
   (list (cons 'port-base (setting-default (setting-named 'port-base))))))

(define (settings-port-base settings)
  (cond ((get-environment-variable "MURDOCH_PORT_BASE") => string->number)
        (else (cdr (assq 'port-base settings)))))

;;> The port for a guest, an address space the file does not name (a REPL
;;> that joins the lab): 0, a free one that the kernel chooses, which the
;;> guest says in its hellos; ports derived from process ids clashed.
(define (lab-guest-port lab) 0)

;;> Reads the lab file at \var{path}.  Errors name the file, the line and
;;> the fault.
(define (read-lab path)
  (let* ((source (read-source path))
         (data (car source)))
    (parameterize ((clause-lines (cdr source)))
      (cond ((null? data)
             (error (string-append path ": the file is empty; a lab file holds one"
                                   " (lab NAME CLAUSE ...) form")))
            ((pair? (cdr data))
             (lab-file-error path (car (cadr data))
                             (string-append "a second form; a lab file holds one"
                                            " (lab NAME CLAUSE ...) form")))
            ((not (let ((form (car (car data))))
                    (and (pair? form) (eq? (car form) 'lab) (pair? (cdr form))
                         (symbol? (cadr form)) (list? (cddr form)))))
             (lab-file-error path (car (car data))
                             "a lab file holds one (lab NAME CLAUSE ...) form"))
            (else (parse-lab path (car (car data))))))))

;;> The data of the Scheme file at \var{path} and where they are:
;;> (((DATUM . LINE) ...) (LIST . LINE) ...), every list within by eq?.
;;> The end of the file inside a list is an error that names the list
;;> most likely left open: the first whose column a later line starts at
;;> or left of, as when a clause lacks its ), or else the innermost.
;;> Lists are read here, for their lines; other data with read.
(define (read-source path)
  (let ((in (guard (e ((file-error? e)
                        (error (string-append "cannot read " path
                                              ": couldn't open input file"))))
              (open-input-file path))))
    (let ((source (read-source-port path in)))
      (close-input-port in)
      source)))

(define (read-source-port path in)
  (let ((lines '())
        (column 0)                      ; of the next datum, when it starts a line
        (fresh-line? #t)
        (suspect #f))                   ; (LINE COLUMN) of a list that looks open
    (define (skip!)
      (let ((c (peek-char in)))
        (cond ((eof-object? c))
              ((char=? c #\newline)
               (read-char in) (set! column 0) (set! fresh-line? #t) (skip!))
              ((char-whitespace? c) (read-char in) (set! column (+ column 1)) (skip!))
              ((char=? c #\;)
               (read-line in) (set! column 0) (set! fresh-line? #t) (skip!)))))
    (define (fail line why)
      (error (string-append path ":" (number->string line) ": " why)))
    ;; The next datum; open: ((LINE COLUMN) ...) of the lists it is in,
    ;; innermost first, COLUMN #f for one that did not start its line.
    (define (datum open)
      (skip!)
      (let ((line (port-line in))
            (col (and fresh-line? column))
            (c (peek-char in)))
        (set! fresh-line? #f)
        (if (and col (not suspect))
            (set! suspect (find (lambda (o)
                                  (and (cadr o) (< (car o) line) (<= col (cadr o))))
                                (reverse open))))
        (cond
         ((eof-object? c) c)
         ((char=? c #\() (read-char in) (read-list line (cons (list line col) open)))
         ((char=? c #\)) (read-char in) (fail line "a ) that closes nothing"))
         (else
          (guard (e (#t (fail line (string-append "cannot read this: "
                                                  (condition-message e)))))
            (read in))))))
    (define (read-list line open)
      (let loop ((items '()))
        (skip!)
        (let ((next (peek-char in)))
          (cond
           ((eof-object? next)
            (fail (car (or suspect (car open)))
                  "this list has no closing ): the file ends inside it"))
           ((char=? next #\)) (read-char in)
            (let ((form (reverse items)))
              (set! lines (cons (cons form line) lines))
              form))
           ((char=? next #\.) (read-char in)
            (if (delimiter? (peek-char in))
                (let ((tail (datum open)))
                  (skip!)
                  (if (not (eqv? (peek-char in) #\)))
                      (fail line "a dotted list ends after one datum"))
                  (read-char in)
                  (let ((form (append-reverse items tail)))
                    (set! lines (cons (cons form line) lines))
                    form))
                (loop (cons (dotted-token in) items))))
           (else (loop (cons (datum open) items)))))))
    (let loop ((data '()))
      (skip!)
      (let* ((line (port-line in))
             (d (datum '())))
        (if (eof-object? d)
            (cons (reverse data) lines)
            (loop (cons (cons d line) data)))))))

(define (delimiter? c)
  (or (eof-object? c) (char-whitespace? c) (memv c '(#\( #\) #\" #\;))))

;; A number or symbol that starts with the . already read, as .5 or ...
(define (dotted-token in)
  (let loop ((chars '(#\.)))
    (if (delimiter? (peek-char in))
        (let ((text (list->string (reverse chars))))
          (or (string->number text) (string->symbol text)))
        (loop (cons (read-char in) chars)))))

(define (parse-lab path form)
  (let* ((clauses (cddr form))
         (settings (read-settings path clauses))
         (base (settings-port-base settings))
         (interface (cdr (assq 'interface settings)))
         (lab (make-lab (cadr form) (path-directory path) settings
                        (let loop ((cs clauses) (i 0) (acc '()))
                          (cond
                           ((null? cs) (reverse acc))
                           ((and (pair? (car cs)) (eq? (caar cs) 'aspace))
                            (loop (cdr cs) (+ i 1)
                                  (cons (parse-aspace path (car cs) i base interface)
                                        acc)))
                           (else (loop (cdr cs) i acc))))
                        clauses)))
    (check-lab path lab)
    (check-room path clauses)
    lab))

;; What no one clause shows: two address spaces of one name, two things
;; on one port, a code file that is not there.  The one of two named is
;; the later, with the line of the other.
(define (check-lab path lab)
  (let loop ((as (lab-aspaces lab)))
    (when (pair? as)
      (cond ((find (lambda (b) (eq? (lab-aspace-uid b) (lab-aspace-uid (car as))))
                   (cdr as))
             => (lambda (b)
                  (lab-file-error
                   path (lab-aspace-form b)
                   (string-append "two address spaces of this name: the other"
                                  (line-words (lab-aspace-form (car as))))))))
      (loop (cdr as))))
  (let loop ((ports (lab-ports lab)))
    (when (pair? ports)
      (cond ((find (lambda (p) (= (listener-port p) (listener-port (car ports))))
                   (cdr ports))
             => (lambda (p)
                  (lab-file-error path (listener-clause p)
                                  (string-append
                                   "two things on port "
                                   (number->string (listener-port p)) ": "
                                   (listener-what (car ports))
                                   (line-words (listener-clause (car ports)))
                                   ", and " (listener-what p)
                                   " (address spaces listen at port-base + i, robots'"
                                   " trip servers at port-base + 100 + i)")))))
      (loop (cdr ports))))
  (for-each (lambda (file)
              (if (not (file-exists? (lab-path lab file)))
                  (lab-file-error path (clause 'code (lab-clauses lab))
                                  (string-append "no such file " file))))
            (lab-setting lab 'code)))

(define (line-words c)
  (cond ((clause-line c) => (lambda (n) (string-append " on line " (number->string n))))
        (else "")))

;; What listens on a port of the lab, and the clause that puts it there.
(define-record-type listener
  (make-listener port what clause)
  listener?
  (port listener-port)
  (what listener-what)
  (clause listener-clause))

;; Every listener of the lab's address spaces and robots, in file order.
(define (lab-ports lab)
  (append-map
   (lambda (a)
     (let ((name (symbol->string (lab-aspace-uid a)))
           (form (lab-aspace-form a)))
       (cons (make-listener (lab-aspace-port a) (string-append "the address space " name)
                            form)
             (if (lab-aspace-clause a 'robot)
                 (list (make-listener (lab-trip-port lab a)
                                      (string-append "the trip server of the robot " name)
                                      form))
                 '()))))
   (lab-aspaces lab)))

;; form was checked by check-inside.
(define (parse-aspace path form index base interface)
  (let ((clauses (cddr form)))
    (make-lab-aspace (cadr form) index
                     (clause-value 'host clauses interface)
                     (clause-value 'port clauses (+ base index))
                     clauses form)))

(define (path-directory path)
  (let loop ((i (- (string-length path) 1)))
    (cond ((< i 0) ".")
          ((char=? (string-ref path i) #\/)
           (if (zero? i) "/" (substring path 0 i)))
          (else (loop (- i 1))))))

;;> A path named in the lab file, which is relative to the file.
(define (lab-path lab file)
  (if (and (> (string-length file) 0) (char=? (string-ref file 0) #\/))
      file
      (string-append (lab-directory lab) "/" file)))

;;> The address space of the lab named \var{uid}, or #f.
(define (lab-aspace-by-uid lab uid)
  (find (lambda (a) (eq? (lab-aspace-uid a) uid)) (lab-aspaces lab)))

;;> The port of the trip server of robot \var{a}: its (robot (trip-port N))
;;> or port-base + 100 + its index.
(define (lab-trip-port lab a)
  (robot-setting a 'trip-port (+ (lab-port-base lab) 100 (lab-aspace-index a))))

;;> The host of the trip server of robot \var{a}: its (robot (trip-host
;;> "ADDR")), for a robot whose address space runs on another host than
;;> the simulator, or else its address space's host.
(define (lab-trip-host lab a)
  (robot-setting a 'trip-host (lab-aspace-host a)))

(define (robot-setting a key default)
  (let ((robot (lab-aspace-clause a 'robot)))
    (cond ((and robot (find (lambda (c) (and (pair? c) (eq? (car c) key) (pair? (cdr c))))
                            (cdr robot)))
           => cadr)
          (else default))))

;;> The uids of the lab's robots, in file order.
(define (lab-robots lab)
  (map lab-aspace-uid
       (filter (lambda (a) (lab-aspace-clause a 'robot)) (lab-aspaces lab))))

;;; The key

(define key-bytes 32)

;;> The lab's key as a bytevector, read from its key file.  When the file
;;> does not exist it is made: written under a temporary name with mode
;;> 0600 and linked into place, so that peers starting at once all end up
;;> with the one key that won, and none reads a half-written file.
(define (lab-key lab)
  (let ((file (lab-path lab (lab-setting lab 'key-file))))
    (if (not (file-exists? file))
        (make-key-file file))
    (let ((hex (call-with-input-file file read-line)))
      (if (or (eof-object? hex) (< (string-length hex) 32))
          (error (string-append "the lab's key file is too short " file)))
      (string->utf8 hex))))

(define (make-key-file file)
  (let ((temp (string-append file "." (number->string (current-process-id))
                             ".new")))
    (let ((fd (open temp (bitwise-ior open/write open/create open/exclusive)
                    #o600)))
      (if (not fd) (error (string-append "cannot create the key file " temp)))
      (let ((out (open-output-file-descriptor fd)))
        (write-string (random-hex key-bytes) out)
        (newline out)
        (close-output-port out)))
    (link-file temp file)               ; fails harmlessly if another won
    (delete-file temp)))

(define (random-hex n)
  (let ((bytes (call-with-port (open-binary-input-file "/dev/urandom")
                 (lambda (in) (read-bytevector n in)))))
    (apply string-append
           (map (lambda (b)
                  (string-append (if (< b 16) "0" "") (number->string b 16)))
                (bytevector->list bytes)))))

(define (bytevector->list bv)
  (let loop ((i (- (bytevector-length bv) 1)) (acc '()))
    (if (< i 0) acc (loop (- i 1) (cons (bytevector-u8-ref bv i) acc)))))
